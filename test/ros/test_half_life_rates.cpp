// forget_half_life through the node: two inputs of one map, laser_1 stamped at 10 Hz and laser_2
// at 40 Hz, each with a wall straight ahead for 1 s, then the wall 1 m farther for 0.3 s. Each
// input's period comes from its own stamps, so both walls are forgotten by the same amount per
// second (with gamma per scan, the 40 Hz wall would be forgotten four times as fast).
#include <gtest/gtest.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <cmath>
#include <mutex>

#include "room.h"
#include "wavog_mapping/MapperStatus.h"

namespace {

constexpr double kHalfLife = 0.25;  // test/half_life_rates.test
constexpr int kCentre = room::kBeams / 2;

std::mutex g_mutex;
wavog_mapping::MapperStatus::ConstPtr g_status;
nav_msgs::OccupancyGrid::ConstPtr g_map;

// The wall point straight ahead of sensor s (its central beam), 1 cm before the hit.
void wallAhead(const room::Sensor& s, double* x, double* y) {
  const auto scan = room::scanOf(s, ros::Time(1.0));
  room::aheadOf(s, scan->ranges[kCentre] - 0.01, x, y);
}

// 0..100 of an OccupancyGrid from log-odds x.
double percent(double x) { return 100.0 / (1.0 + std::exp(-x)); }

// The closed form for one input: the first scan forgets by gamma (its period is unknown), the
// others by their period; `wall` s of the wall, then `gone` s of free space.
double expectedPercent(double period, double wall, double gone) {
  const double occ = 3.5, emp = -2.0, gamma = 0.3;  // the "forget" defaults
  double x = gamma * occ;
  x = occ + (x - occ) * std::exp2(-(wall - period) / kHalfLife);
  x = emp + (x - emp) * std::exp2(-gone / kHalfLife);
  return percent(x);
}

TEST(HalfLifeRates, InputsOfDifferentRatesForgetAlikePerSecond) {
  ros::NodeHandle nh;
  const auto& sensors = room::sensors();
  ros::Publisher pub[2] = {nh.advertise<sensor_msgs::LaserScan>("scan_1", 200),
                           nh.advertise<sensor_msgs::LaserScan>("scan_2", 200)};
  for (auto& p : pub) room::waitForSubscribers(p, 1, 20.0);
  const double periods[2] = {0.1, 0.025};
  const ros::Time t0 = ros::Time::now();
  int published[2] = {0, 0};
  // Stamp order per input; the two inputs see disjoint walls.
  for (int k = 0; k < 2; ++k) {
    const int wall_scans = static_cast<int>(std::lround(1.0 / periods[k]));
    const int gone_scans = static_cast<int>(std::lround(0.3 / periods[k]));
    for (int i = 0; i < wall_scans + gone_scans; ++i) {
      auto scan =
          room::scanOf(sensors[static_cast<std::size_t>(k)], t0 + ros::Duration(i * periods[k]));
      if (i >= wall_scans) {
        for (float& r : scan->ranges) r += 1.0f;  // the wall has gone 1 m back
      }
      pub[k].publish(scan);
      ++published[k];
      ros::WallDuration(0.005).sleep();
    }
  }
  const auto status = room::waitLatest(
      &g_mutex, &g_status,
      [&](const wavog_mapping::MapperStatus& s) {
        return s.inputs.size() == 2 &&
               s.inputs[0].integrated == static_cast<unsigned>(published[0]) &&
               s.inputs[1].integrated == static_cast<unsigned>(published[1]);
      },
      30.0);
  ASSERT_TRUE(status);
  ASSERT_EQ(status->inputs[0].integrated, static_cast<unsigned>(published[0]));
  ASSERT_EQ(status->inputs[1].integrated, static_cast<unsigned>(published[1]));
  // A map published after the last scan was integrated.
  const ros::WallTime integrated_at = ros::WallTime::now();
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    g_map.reset();
  }
  const auto map = room::waitLatest(
      &g_mutex, &g_map, [](const nav_msgs::OccupancyGrid&) { return true; }, 10.0);
  ASSERT_TRUE(map);
  ASSERT_GT(ros::WallTime::now(), integrated_at);
  double p[2];
  for (int k = 0; k < 2; ++k) {
    double x, y;
    wallAhead(sensors[static_cast<std::size_t>(k)], &x, &y);
    p[k] = room::cellAt(*map, x, y);
    ASSERT_GE(p[k], 0) << "laser_" << k + 1 << "'s wall cell is not in the map or unknown";
    EXPECT_NEAR(p[k], expectedPercent(periods[k], 1.0, 0.3), 3.0) << "laser_" << k + 1;
  }
  EXPECT_NEAR(p[0], p[1], 3.0) << "10 Hz and 40 Hz walls forgotten differently per second";
  // Gamma per scan would leave the 40 Hz wall far lower (see test_forget_half_life).
  EXPECT_GT(p[1], 40.0);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_half_life_rates");
  ros::NodeHandle nh;
  tf2_ros::StaticTransformBroadcaster static_tf;
  static_tf.sendTransform(room::staticTree());
  auto status_sub = room::keepLatest<wavog_mapping::MapperStatus>(nh, "wavog_mapping/status", 10,
                                                                  &g_mutex, &g_status);
  auto map_sub = room::keepLatest<nav_msgs::OccupancyGrid>(nh, "map", 2, &g_mutex, &g_map);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  ros::shutdown();
  return result;
}
