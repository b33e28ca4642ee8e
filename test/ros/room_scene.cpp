// Publishes the test room (static tf + four synthetic scanners at 10 Hz) until shut down; used by
// `make rviz-check` to show the mapper's output in rviz. Topics: scan_1..scan_4 (remappable).
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include "room.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "room_scene");
  ros::NodeHandle nh;
  tf2_ros::StaticTransformBroadcaster static_tf;
  static_tf.sendTransform(room::staticTree());
  std::vector<ros::Publisher> pubs;
  for (int i = 1; i <= 4; ++i) {
    pubs.push_back(nh.advertise<sensor_msgs::LaserScan>("scan_" + std::to_string(i), 10));
  }
  ros::Rate rate(10.0);
  while (ros::ok()) {
    const ros::Time stamp = ros::Time::now();
    for (std::size_t i = 0; i < pubs.size(); ++i)
      pubs[i].publish(room::scanOf(room::sensors()[i], stamp));
    ros::spinOnce();
    rate.sleep();
  }
  return 0;
}
