// The reflection layers of the node (reflection: true): `reflection` (latched) and
// reflection_scale_<s> next to map and map_scale_<s>, over the same boxes. laser_1 sees the room
// for 2 s at 10 Hz, then its wall ahead goes 1 m back for 1 s: with forgetting the old wall cell's
// p falls from 100 (every beam ended there) towards 0, free cells read 0, unseen cells -1.
#include <gtest/gtest.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <mutex>

#include "room.h"
#include "wavog_mapping/MapperStatus.h"

namespace {

constexpr int kCentre = room::kBeams / 2;

std::mutex g_mutex;
wavog_mapping::MapperStatus::ConstPtr g_status;
nav_msgs::OccupancyGrid::ConstPtr g_map, g_reflection, g_reflection_2;

nav_msgs::OccupancyGrid::ConstPtr latest(const nav_msgs::OccupancyGrid::ConstPtr* which) {
  return room::waitLatest(
      &g_mutex, which, [](const nav_msgs::OccupancyGrid& g) { return !g.data.empty(); }, 10.0);
}

// Publishes `n` scans of laser_1 at 10 Hz from t0 + first * 0.1, the ranges lengthened by `back`.
void publishScans(ros::Publisher& pub, const ros::Time& t0, int first, int n, float back) {
  for (int i = first; i < first + n; ++i) {
    auto scan = room::scanOf(room::sensors()[0], t0 + ros::Duration(0.1 * i));
    for (float& r : scan->ranges) r += back;
    pub.publish(scan);
    ros::WallDuration(0.005).sleep();
  }
}

void waitIntegrated(unsigned n) {
  const auto s = room::waitLatest(
      &g_mutex, &g_status,
      [n](const wavog_mapping::MapperStatus& st) {
        return !st.inputs.empty() && st.inputs[0].integrated >= n;
      },
      30.0);
  ASSERT_TRUE(s);
  ASSERT_EQ(s->inputs[0].integrated, n);
  std::lock_guard<std::mutex> lock(g_mutex);
  g_map.reset();
  g_reflection.reset();
  g_reflection_2.reset();
}

TEST(ReflectionTopics, LayersFollowHitsAndMisses) {
  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<sensor_msgs::LaserScan>("scan_1", 100);
  room::waitForSubscribers(pub, 1, 20.0);
  const room::Sensor& laser = room::sensors()[0];
  const double wall = room::scanOf(laser, ros::Time(1.0))->ranges[kCentre];
  double wx, wy, fx, fy;
  room::aheadOf(laser, wall - 0.01, &wx, &wy);  // the wall cell
  room::aheadOf(laser, wall / 2, &fx, &fy);     // free space
  const ros::Time t0 = ros::Time::now();

  publishScans(pub, t0, 0, 20, 0.0f);
  waitIntegrated(20);
  auto map = latest(&g_map), reflection = latest(&g_reflection), coarse = latest(&g_reflection_2);
  ASSERT_TRUE(map && reflection && coarse);
  // Same box, resolution and origin as the occupancy layer of its scale.
  EXPECT_EQ(reflection->info.width, map->info.width);
  EXPECT_EQ(reflection->info.height, map->info.height);
  EXPECT_DOUBLE_EQ(reflection->info.origin.position.x, map->info.origin.position.x);
  EXPECT_FLOAT_EQ(coarse->info.resolution, 4 * map->info.resolution);
  EXPECT_EQ(room::cellAt(*reflection, wx, wy), 100);                   // every beam ended there
  EXPECT_EQ(room::cellAt(*reflection, fx, fy), 0);                     // every beam crossed it
  EXPECT_EQ(room::cellAt(*reflection, room::kUnkX, room::kUnkY), -2);  // outside the grid
  // Unknown inside the grid: where the occupancy layer is unknown, so is the reflection.
  std::size_t unknown_both = 0, mismatched = 0;
  for (std::size_t i = 0; i < map->data.size(); ++i) {
    const bool a = map->data[i] < 0, b = reflection->data[i] < 0;
    unknown_both += a && b;
    mismatched += a != b;
  }
  EXPECT_EQ(mismatched, 0u);
  EXPECT_GT(unknown_both, 0u);
  const int coarse_wall = room::cellAt(*coarse, wx, wy);
  EXPECT_GT(coarse_wall, 0);
  EXPECT_LT(coarse_wall, 100);  // a 4 x 4 block holds the wall and free cells: a ratio of sums

  // The wall goes 1 m back: the old wall cell is crossed by the beams now.
  publishScans(pub, t0, 20, 10, 1.0f);
  waitIntegrated(30);
  reflection = latest(&g_reflection);
  ASSERT_TRUE(reflection);
  const int after = room::cellAt(*reflection, wx, wy);
  EXPECT_GE(after, 0);
  EXPECT_LT(after, 10) << "forgetting (gamma 0.3 per scan) leaves 0.7^10 of the hits";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_reflection_topics");
  ros::NodeHandle nh;
  tf2_ros::StaticTransformBroadcaster static_tf;
  static_tf.sendTransform(room::staticTree());
  auto status_sub = room::keepLatest<wavog_mapping::MapperStatus>(nh, "wavog_mapping/status", 10,
                                                                  &g_mutex, &g_status);
  auto map_sub = room::keepLatest<nav_msgs::OccupancyGrid>(nh, "map", 2, &g_mutex, &g_map);
  auto refl_sub =
      room::keepLatest<nav_msgs::OccupancyGrid>(nh, "reflection", 2, &g_mutex, &g_reflection);
  auto refl2_sub = room::keepLatest<nav_msgs::OccupancyGrid>(nh, "reflection_scale_2", 2, &g_mutex,
                                                             &g_reflection_2);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  ros::shutdown();
  return result;
}
