// wavog_static_tf: publishes one latched transform on /tf_static, for a robot or a bag without tf
// for its laser (Debian packages no static_transform_publisher). The same arguments as tf2_ros'
// static_transform_publisher:
//   wavog_static_tf x y z yaw pitch roll parent_frame child_frame     (metres, radians)
// With the private parameter ~parent_frame_from set to the name of a parameter (e.g.
// /wavog_mapping/map_frame), the parent frame is read from that parameter when it exists, so a
// launch file can hold the laser fixed to whatever map frame the mapper's YAML configures.
// Leading '/' of the frame ids (tf1-era names) are stripped. Exit status 2 on bad arguments.
#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>
#include <tf2/LinearMath/Quaternion.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

constexpr const char* kUsage =
    "usage: wavog_static_tf x y z yaw pitch roll parent_frame child_frame\n"
    "  (metres, radians; ~parent_frame_from: parameter naming the parent frame, if set)\n";

std::string stripSlash(const std::string& frame) {
  std::string::size_type first = frame.find_first_not_of('/');
  return first == std::string::npos ? std::string() : frame.substr(first);
}

bool parseNumber(const std::string& text, double* value) {
  char* end = nullptr;
  *value = std::strtod(text.c_str(), &end);
  return !text.empty() && end == text.c_str() + text.size() && std::isfinite(*value);
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "wavog_static_tf", ros::init_options::AnonymousName);
  std::vector<std::string> args;
  ros::removeROSArgs(argc, argv, args);  // args[0] is the program
  if (args.size() != 9) {
    std::fputs(kUsage, stderr);
    return 2;
  }
  const char* names[6] = {"x", "y", "z", "yaw", "pitch", "roll"};
  double v[6];
  for (int i = 0; i < 6; ++i) {
    if (!parseNumber(args[static_cast<size_t>(i) + 1], &v[i])) {
      std::fprintf(stderr, "wavog_static_tf: %s: not a finite number: '%s'\n%s", names[i],
                   args[static_cast<size_t>(i) + 1].c_str(), kUsage);
      return 2;
    }
  }
  std::string parent = stripSlash(args[7]);
  const std::string child = stripSlash(args[8]);

  ros::NodeHandle pnh("~");
  std::string parent_param;
  if (pnh.getParam("parent_frame_from", parent_param) && !parent_param.empty()) {
    std::string configured;
    if (ros::param::get(parent_param, configured) && !stripSlash(configured).empty()) {
      parent = stripSlash(configured);
    }
  }
  if (parent.empty() || child.empty() || parent == child) {
    std::fprintf(stderr, "wavog_static_tf: parent '%s' and child '%s' must be distinct, non-empty"
                 " frame ids\n", parent.c_str(), child.c_str());
    return 2;
  }

  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time::now();
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform.translation.x = v[0];
  t.transform.translation.y = v[1];
  t.transform.translation.z = v[2];
  tf2::Quaternion q;
  q.setRPY(v[5], v[4], v[3]);
  t.transform.rotation.x = q.x();
  t.transform.rotation.y = q.y();
  t.transform.rotation.z = q.z();
  t.transform.rotation.w = q.w();

  tf2_ros::StaticTransformBroadcaster broadcaster;
  broadcaster.sendTransform(t);
  ROS_INFO("wavog_static_tf: %s -> %s: xyz (%g, %g, %g), yaw/pitch/roll (%g, %g, %g) rad",
           parent.c_str(), child.c_str(), v[0], v[1], v[2], v[3], v[4], v[5]);
  ros::spin();
  return 0;
}
