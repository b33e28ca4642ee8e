// The synthetic drive shared by the placement test (test/ros/test_scan_placement.cpp) and the
// offline bag test (test/tools/test_offline.cpp): a robot drives along x at kSpeed from t0 with
// tf at 100 Hz; a laser mounted upside down kMount ahead of base_link times its beams
// (time_increment), so placement mirrors and re-bins every sweep.
#ifndef WAVOG_MAPPING_TEST_ROS_DRIVING_LASER_H_
#define WAVOG_MAPPING_TEST_ROS_DRIVING_LASER_H_

#include <geometry_msgs/TransformStamped.h>
#include <sensor_msgs/LaserScan.h>

#include <cmath>
#include <string>
#include <vector>

namespace driving_laser {

constexpr int kBeams = 181;
constexpr int kScans = 20;               // one every 0.1 s
constexpr double kSpeed = 1.0;           // m/s along +x
constexpr double kTimeIncrement = 1e-4;  // s between beams
constexpr double kSweep = kTimeIncrement * (kBeams - 1);
constexpr double kMount = 0.2;      // laser ahead of base_link (m)
constexpr double kTfSeconds = 2.0;  // tf known over [t0, t0 + kTfSeconds]
constexpr int kShortBeam = 135;     // 1 m at +45 deg in the laser frame (-45 deg in the map)
constexpr int kErrorBeam = 10;      // 0: an error code, invalid (REP 117)
inline const ros::Time kT0{1000, 0};

/// parent <- child: x along parent's x, then yaw about z and roll about x (q_z(yaw) * q_x(roll)).
inline geometry_msgs::TransformStamped transform(const std::string& parent,
                                                 const std::string& child, double x, double yaw,
                                                 double roll, const ros::Time& t) {
  geometry_msgs::TransformStamped ts;
  ts.header.stamp = t;
  ts.header.frame_id = parent;
  ts.child_frame_id = child;
  ts.transform.translation.x = x;
  const double cy = std::cos(yaw / 2), sy = std::sin(yaw / 2);
  const double cr = std::cos(roll / 2), sr = std::sin(roll / 2);
  ts.transform.rotation.w = cy * cr;
  ts.transform.rotation.x = cy * sr;
  ts.transform.rotation.y = sy * sr;
  ts.transform.rotation.z = sy * cr;
  return ts;
}

/// The static mount base_link <- laser (upside down), stamped t0.
inline geometry_msgs::TransformStamped mount(const std::string& laser_frame) {
  return transform("base_link", laser_frame, kMount, 0.0, M_PI, kT0);
}

/// map <- base_link at every 10 ms of the drive.
inline std::vector<geometry_msgs::TransformStamped> drive() {
  std::vector<geometry_msgs::TransformStamped> out;
  for (int k = 0; k <= static_cast<int>(std::lround(100 * kTfSeconds)); ++k) {
    const ros::Time t = kT0 + ros::Duration(0.01 * k);
    out.push_back(transform("map", "base_link", kSpeed * 0.01 * k, 0.0, 0.0, t));
  }
  return out;
}

/// The scan stamped t0 + t in `frame`: 3 m everywhere but the short and the error beam.
inline sensor_msgs::LaserScan scanAt(double t, const std::string& frame) {
  sensor_msgs::LaserScan s;
  s.header.stamp = kT0 + ros::Duration(t);
  s.header.frame_id = frame;
  s.angle_min = static_cast<float>(-M_PI / 2);
  s.angle_increment = static_cast<float>(M_PI / (kBeams - 1));
  s.angle_max = static_cast<float>(M_PI / 2);
  s.time_increment = static_cast<float>(kTimeIncrement);
  s.range_min = 0.05f;
  s.range_max = 30.0f;
  s.ranges.assign(kBeams, 3.0f);
  s.ranges[kShortBeam] = 1.0f;
  s.ranges[kErrorBeam] = 0.0f;
  return s;
}

/// Stamp offset (s from t0) of scan i.
inline double scanTime(int i) { return 0.1 * i + 0.005; }

}  // namespace driving_laser

#endif  // WAVOG_MAPPING_TEST_ROS_DRIVING_LASER_H_
