// Motion compensation through ROS (sim time, driven by this test): a scanner drives at 3 m/s
// towards the wall x = 3.95 while sweeping for 0.1 s. The compensating mapper puts the wall where
// it is; the one with motion_compensation off smears it towards the robot.
#include <gtest/gtest.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include <atomic>
#include <mutex>
#include <thread>

#include "room.h"
#include "wavog_mapping/MapperStatus.h"

namespace {

constexpr double kStart = 100.0;  // sim time the drive starts (s)
constexpr double kDrive = 1.0;    // drive duration (s)
constexpr double kSpeed = 3.0;    // m/s along +x
constexpr double kSweep = 0.1;    // sweep duration (s)
constexpr double kX0 = -2.0;      // x at the start of the drive

double xAt(double t) { return kX0 + kSpeed * std::min(std::max(t - kStart, 0.0), kDrive); }

/// The scan started at t0 by a level scanner at (x(t), 0) heading +x, beam i at t0 + i * dt.
sensor_msgs::LaserScan::Ptr sweep(double t0) {
  auto scan = boost::make_shared<sensor_msgs::LaserScan>();
  scan->header.frame_id = "laser";
  scan->header.stamp = ros::Time(t0);
  scan->angle_min = static_cast<float>(-room::kPi / 2);
  scan->angle_increment = static_cast<float>(room::kPi / 360);
  scan->angle_max = static_cast<float>(scan->angle_min + 360 * scan->angle_increment);
  scan->time_increment = static_cast<float>(kSweep / 360);
  scan->scan_time = static_cast<float>(kSweep);
  scan->range_min = 0.1f;
  scan->range_max = 80.0f;
  for (int i = 0; i <= 360; ++i) {
    const double a = scan->angle_min + i * static_cast<double>(scan->angle_increment);
    const double x = xAt(t0 + i * static_cast<double>(scan->time_increment));
    scan->ranges.push_back(static_cast<float>(room::castRay(x, 0.0, std::cos(a), std::sin(a))));
  }
  return scan;
}

std::mutex g_mutex;
nav_msgs::OccupancyGrid::ConstPtr g_map, g_raw;
wavog_mapping::MapperStatus::ConstPtr g_status;
std::atomic<double> g_now{kStart - 1.0};

TEST(MotionCompensation, WallStaysSharpOnlyWithCompensation) {
  // Wait until the drive is over and both maps were published after it.
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(40.0);
  const ros::Time done(kStart + kDrive + 0.5);
  while (ros::ok() && ros::WallTime::now() < end) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      if (g_map && g_raw && g_map->header.stamp > done && g_raw->header.stamp > done) break;
    }
    ros::WallDuration(0.05).sleep();
  }
  std::lock_guard<std::mutex> lock(g_mutex);
  ASSERT_TRUE(g_map && g_raw);
  // Straight ahead (y in [0, 0.1)): the wall is in cell [3.9, 4.0).
  EXPECT_GT(room::cellAt(*g_map, 3.95, 0.05), 50);
  EXPECT_LT(room::cellAt(*g_map, 3.85, 0.05), 50) << "compensated wall smeared";
  EXPECT_LT(room::cellAt(*g_map, 3.75, 0.05), 50) << "compensated wall smeared";
  // Without compensation the beam ahead (half a sweep, 0.15 m of motion) lands short.
  const int raw_short =
      std::max(room::cellAt(*g_raw, 3.85, 0.05), room::cellAt(*g_raw, 3.75, 0.05));
  EXPECT_GT(raw_short, 50) << "the test does not show the effect";
  // Two tf lookups per scan succeeded for every scan (no fallback to the uncompensated pose).
  ASSERT_TRUE(g_status);
  ASSERT_EQ(g_status->inputs.size(), 1u);
  EXPECT_GE(g_status->inputs[0].integrated, 10u);
  EXPECT_EQ(g_status->inputs[0].motion_fallbacks, 0u);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_motion");
  ros::NodeHandle nh;
  auto clock_pub = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  auto scan_pub = nh.advertise<sensor_msgs::LaserScan>("scan_1", 20);
  auto map_sub = room::keepLatest<nav_msgs::OccupancyGrid>(nh, "map", 2, &g_mutex, &g_map);
  auto raw_sub = room::keepLatest<nav_msgs::OccupancyGrid>(nh, "map_raw", 2, &g_mutex, &g_raw);
  auto status_sub = room::keepLatest<wavog_mapping::MapperStatus>(nh, "wavog_mapping/status", 10,
                                                                  &g_mutex, &g_status);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  room::waitForSubscribers(scan_pub, 2, 20.0);  // both mappers, before sim time moves
  tf2_ros::TransformBroadcaster tf;
  tf2_ros::StaticTransformBroadcaster static_tf;
  std::atomic<bool> running{true};
  // Each 10 ms of wall time: sim time +5 ms, /clock, map -> base_link at that time; a scan is
  // published once its sweep is over (as drivers do), stamped with its first beam.
  std::thread sim([&] {
    geometry_msgs::TransformStamped laser;
    laser.header.frame_id = "base_link";
    laser.child_frame_id = "laser";
    laser.transform.rotation.w = 1.0;
    static_tf.sendTransform(laser);
    double next_scan = kStart - 0.5;
    while (running && ros::ok()) {
      const double t = g_now;
      rosgraph_msgs::Clock c;
      c.clock = ros::Time(t);
      clock_pub.publish(c);
      geometry_msgs::TransformStamped base;
      base.header.stamp = c.clock;
      base.header.frame_id = "map";
      base.child_frame_id = "base_link";
      base.transform.translation.x = xAt(t);
      base.transform.rotation.w = 1.0;
      tf.sendTransform(base);
      if (t >= next_scan + kSweep + 0.02 && next_scan <= kStart + kDrive) {
        scan_pub.publish(sweep(next_scan));
        next_scan += 0.1;
      }
      ros::WallDuration(0.01).sleep();
      g_now = t + 0.005;
    }
  });
  const int result = RUN_ALL_TESTS();
  running = false;
  sim.join();
  return result;
}
