// Synthetic test world shared by the rostests: a rectangular room, a robot with four LMS-291-like
// scanners on its corners (one mounted upside down), static tf and ray-cast LaserScans.
#ifndef WAVOG_MAPPING_TEST_ROS_ROOM_H_
#define WAVOG_MAPPING_TEST_ROS_ROOM_H_

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2/LinearMath/Matrix3x3.h>
#include <tf2/LinearMath/Quaternion.h>
#include <tf2/LinearMath/Transform.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

namespace room {

constexpr double kPi = 3.14159265358979323846;
/// Walls: x = +-kHalfX, y = +-kHalfY (map frame, m); on cell centres of a 0.1 m grid.
constexpr double kHalfX = 3.95;
constexpr double kHalfY = 2.95;
constexpr int kBeams = 361;

struct Sensor {
  std::string frame;
  double x, y, yaw, roll;  // in base_link
};

inline const std::vector<Sensor>& sensors() {
  static const std::vector<Sensor> kSensors = {
      {"laser_1", 0.5, 0.4, kPi / 4, 0.0},
      {"laser_2", 0.5, -0.4, -kPi / 4, kPi},  // upside down
      {"laser_3", -0.5, 0.4, 3 * kPi / 4, 0.0},
      {"laser_4", -0.5, -0.4, -3 * kPi / 4, 0.0},
  };
  return kSensors;
}

/// map -> base_link.
inline tf2::Transform basePose() {
  tf2::Quaternion q;
  q.setRPY(0, 0, 0.1);
  return tf2::Transform(q, tf2::Vector3(0.3, 0.2, 0.0));
}

inline tf2::Transform sensorInBase(const Sensor& s) {
  tf2::Quaternion q;
  q.setRPY(s.roll, 0, s.yaw);
  return tf2::Transform(q, tf2::Vector3(s.x, s.y, 0.0));
}

inline geometry_msgs::TransformStamped toMsg(const tf2::Transform& t, const std::string& parent,
                                             const std::string& child) {
  geometry_msgs::TransformStamped m;
  m.header.stamp = ros::Time::now();
  m.header.frame_id = parent;
  m.child_frame_id = child;
  m.transform.translation.x = t.getOrigin().x();
  m.transform.translation.y = t.getOrigin().y();
  m.transform.translation.z = t.getOrigin().z();
  m.transform.rotation.x = t.getRotation().x();
  m.transform.rotation.y = t.getRotation().y();
  m.transform.rotation.z = t.getRotation().z();
  m.transform.rotation.w = t.getRotation().w();
  return m;
}

/// The static tree: map -> base_link -> laser_1..4.
inline std::vector<geometry_msgs::TransformStamped> staticTree() {
  std::vector<geometry_msgs::TransformStamped> tree = {toMsg(basePose(), "map", "base_link")};
  for (const auto& s : sensors()) tree.push_back(toMsg(sensorInBase(s), "base_link", s.frame));
  return tree;
}

/// Distance from (ox, oy) along (dx, dy) to the room's walls.
inline double castRay(double ox, double oy, double dx, double dy) {
  double t = std::numeric_limits<double>::infinity();
  if (dx > 1e-12) t = std::min(t, (kHalfX - ox) / dx);
  if (dx < -1e-12) t = std::min(t, (-kHalfX - ox) / dx);
  if (dy > 1e-12) t = std::min(t, (kHalfY - oy) / dy);
  if (dy < -1e-12) t = std::min(t, (-kHalfY - oy) / dy);
  return t;
}

/// The scan sensor `s` sees of the room (180 deg, 0.5 deg steps, LMS-291-like timing).
inline sensor_msgs::LaserScan::Ptr scanOf(const Sensor& s, const ros::Time& stamp) {
  auto scan = boost::make_shared<sensor_msgs::LaserScan>();
  scan->header.frame_id = s.frame;
  scan->header.stamp = stamp;
  scan->angle_min = static_cast<float>(-kPi / 2);
  scan->angle_increment = static_cast<float>(kPi / 360);
  scan->angle_max = static_cast<float>(scan->angle_min + (kBeams - 1) * scan->angle_increment);
  scan->time_increment = 1.0f / (75.0f * 360.0f);
  scan->scan_time = 1.0f / 37.5f;
  scan->range_min = 0.1f;
  scan->range_max = 80.0f;
  const tf2::Transform pose = basePose() * sensorInBase(s);
  for (int i = 0; i < kBeams; ++i) {
    const double a = scan->angle_min + i * static_cast<double>(scan->angle_increment);
    const tf2::Vector3 d =
        tf2::Transform(pose.getRotation()) * tf2::Vector3(std::cos(a), std::sin(a), 0);
    scan->ranges.push_back(
        static_cast<float>(castRay(pose.getOrigin().x(), pose.getOrigin().y(), d.x(), d.y())));
  }
  return scan;
}

/// A full-circle scan (720 beams, 0.5 deg) of the room taken from (ox, oy) with yaw 0, each range
/// shortened by `shrink` m, in frame `frame` (beams untimed: no motion compensation).
inline sensor_msgs::LaserScan::Ptr circleScan(const std::string& frame, const ros::Time& stamp,
                                              double ox, double oy, double shrink = 0.0) {
  auto scan = boost::make_shared<sensor_msgs::LaserScan>();
  scan->header.frame_id = frame;
  scan->header.stamp = stamp;
  constexpr int kCircleBeams = 720;
  scan->angle_min = static_cast<float>(-kPi);
  scan->angle_increment = static_cast<float>(kPi / 360);
  scan->angle_max =
      static_cast<float>(scan->angle_min + (kCircleBeams - 1) * scan->angle_increment);
  scan->range_min = 0.1f;
  scan->range_max = 80.0f;
  for (int i = 0; i < kCircleBeams; ++i) {
    const double a = scan->angle_min + i * static_cast<double>(scan->angle_increment);
    scan->ranges.push_back(static_cast<float>(castRay(ox, oy, std::cos(a), std::sin(a)) - shrink));
  }
  return scan;
}

/// Value of the grid cell holding map point (x, y); -2 when outside the grid.
inline int cellAt(const nav_msgs::OccupancyGrid& g, double x, double y) {
  const double r = g.info.resolution;
  const auto ix = static_cast<long>(std::floor((x - g.info.origin.position.x) / r));
  const auto iy = static_cast<long>(std::floor((y - g.info.origin.position.y) / r));
  if (ix < 0 || iy < 0 || ix >= static_cast<long>(g.info.width) ||
      iy >= static_cast<long>(g.info.height)) {
    return -2;
  }
  return g.data[static_cast<std::size_t>(iy) * g.info.width + static_cast<std::size_t>(ix)];
}

/// Map point `d` metres straight ahead of sensor `s`.
inline void aheadOf(const Sensor& s, double d, double* x, double* y) {
  const tf2::Vector3 p = basePose() * sensorInBase(s) * tf2::Vector3(d, 0.0, 0.0);
  *x = p.x();
  *y = p.y();
}

// Probe points (map frame).
constexpr double kOccX = 3.95, kOccY = 0.05;     // on the wall x = +3.95
constexpr double kFreeX = 0.05, kFreeY = -1.05;  // inside the room
constexpr double kUnkX = -6.0, kUnkY = -6.0;     // outside the room

/// A grid's geometry as text (size, resolution, origin; not map_load_time): compared with
/// EXPECT_EQ, a failure shows both grids.
inline std::string geometry(const nav_msgs::MapMetaData& info) {
  const auto& p = info.origin.position;
  const auto& q = info.origin.orientation;
  std::ostringstream s;
  s.precision(17);
  s << info.width << " x " << info.height << " cells of " << info.resolution << " m, origin ("
    << p.x << ", " << p.y << ", " << p.z << "), orientation (" << q.x << ", " << q.y << ", " << q.z
    << ", " << q.w << ")";
  return s.str();
}

/// Subscribes to `topic` and keeps its latest message in *latest, written under *mutex.
template <typename M>
ros::Subscriber keepLatest(ros::NodeHandle& nh, const std::string& topic, std::uint32_t queue,
                           std::mutex* mutex, boost::shared_ptr<const M>* latest) {
  return nh.subscribe<M>(topic, queue,
                         boost::function<void(const boost::shared_ptr<const M>&)>(
                             [mutex, latest](const boost::shared_ptr<const M>& m) {
                               std::lock_guard<std::mutex> lock(*mutex);
                               *latest = m;
                             }));
}

/// Waits (wall time, at most `timeout` s) until `pub` has `n` subscribers or more.
inline void waitForSubscribers(const ros::Publisher& pub, std::uint32_t n, double timeout) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::WallTime::now() < end && pub.getNumSubscribers() < n) {
    ros::WallDuration(0.05).sleep();
  }
}

/// Waits (wall time, at most `timeout` s) until the latest message kept by keepLatest() satisfies
/// `pred`; returns it, or the latest at the timeout (may be null).
template <typename M, typename Pred>
boost::shared_ptr<const M> waitLatest(std::mutex* mutex, const boost::shared_ptr<const M>* latest,
                                      Pred pred, double timeout) {
  const auto get = [&] {
    std::lock_guard<std::mutex> lock(*mutex);
    return *latest;
  };
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < end) {
    const auto m = get();
    if (m && pred(*m)) return m;
    ros::WallDuration(0.05).sleep();
  }
  return get();
}

}  // namespace room

#endif  // WAVOG_MAPPING_TEST_ROS_ROOM_H_
