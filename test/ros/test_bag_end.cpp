// The end of a bag, played by this test as rosbag play --clock would: sim time, frame ids with a
// leading '/' on both inputs and in /tf (tf1 era), scan_1 in the map frame itself (a laser without
// tf, held fixed), scan_2 placed by /tf whose last four scans wait for a transform that never
// comes; then the
// clock and every topic stop. The mapper must strip the slashes with one warning per input,
// integrate every scan of every input (the last four with the latest tf, counted), publish the
// last period once more although its clock stopped, and size /map to the observed room.
#include <gtest/gtest.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <rosgraph_msgs/Log.h>
#include <tf2_msgs/TFMessage.h>

#include <atomic>
#include <mutex>
#include <string>
#include <vector>

#include "room.h"
#include "wavog_mapping/MapperStatus.h"

namespace {

constexpr int kSteps = 30;        // scans per input, 10 Hz of sim time
constexpr int kLastTf = 26;       // tf stops after step 26: steps 26..29 wait for tf (a scan
                                  // needs tf up to its stamp + tf_tolerance)
constexpr double kStart = 100.0;  // sim time of step 0

std::mutex g_mutex;
wavog_mapping::MapperStatus::ConstPtr g_status;
nav_msgs::OccupancyGrid::ConstPtr g_map;
ros::WallTime g_map_receipt;
std::vector<std::string> g_slash_warnings;  // from /rosout
ros::WallTime g_end;                        // wall time at the end of the playback

void play() {
  ros::NodeHandle nh;
  auto clock_pub = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  auto tf_pub = nh.advertise<tf2_msgs::TFMessage>("/tf", 100);
  auto scan1 = nh.advertise<sensor_msgs::LaserScan>("scan_1", 50);
  auto scan2 = nh.advertise<sensor_msgs::LaserScan>("scan_2", 50);
  for (const ros::Publisher* p : {&clock_pub, &tf_pub, &scan1, &scan2}) {
    room::waitForSubscribers(*p, 1, 20.0);
  }
  ros::WallDuration(0.5).sleep();
  tf2::Transform laser_b(tf2::Quaternion::getIdentity(), tf2::Vector3(0.5, 0.0, 0.0));
  for (int i = 0; i < kSteps; ++i) {
    const ros::Time t(kStart + 0.1 * i);
    rosgraph_msgs::Clock c;
    c.clock = t;
    clock_pub.publish(c);
    if (i <= kLastTf) {
      tf2_msgs::TFMessage m;
      m.transforms.push_back(room::toMsg(laser_b, "/map", "/laser_b"));
      m.transforms.back().header.stamp = t;  // tf2's buffer strips the slashes of tf itself
      tf_pub.publish(m);
    }
    scan1.publish(room::circleScan("/map", t, 0.0, 0.0));
    scan2.publish(room::circleScan("/laser_b", t, 0.5, 0.0));
    ros::WallDuration(0.1).sleep();
  }
  std::lock_guard<std::mutex> lock(g_mutex);
  g_end = ros::WallTime::now();
}

TEST(BagEnd, EveryScanOfEveryInputIsIntegratedAndPublished) {
  play();
  const auto s = room::waitLatest(
      &g_mutex, &g_status,
      [](const wavog_mapping::MapperStatus& st) {
        return st.inputs.size() == 2 && st.inputs[0].integrated == kSteps &&
               st.inputs[1].integrated == kSteps;
      },
      20.0);
  ASSERT_TRUE(s);
  ASSERT_EQ(s->inputs.size(), 2u);
  for (const auto& in : s->inputs) {
    EXPECT_EQ(in.received, static_cast<std::uint64_t>(kSteps)) << in.topic;
    EXPECT_EQ(in.integrated, static_cast<std::uint64_t>(kSteps)) << in.topic;
    EXPECT_EQ(in.dropped_bad_frame, 0u) << in.topic;
    EXPECT_EQ(in.dropped_tf_unavailable, 0u) << in.topic;
  }
  EXPECT_EQ(s->inputs[0].integrated_latest_tf, 0u);  // the map frame itself: never waits
  EXPECT_EQ(s->inputs[1].integrated_latest_tf, static_cast<std::uint64_t>(kSteps - kLastTf));

  // The last period reached /map after the clock stopped (the publication timer stopped with it).
  nav_msgs::OccupancyGrid::ConstPtr map;
  const ros::WallTime map_end = ros::WallTime::now() + ros::WallDuration(10.0);
  while (!map && ros::WallTime::now() < map_end) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      if (g_map && g_map_receipt > g_end) map = g_map;
    }
    ros::WallDuration(0.05).sleep();
  }
  ASSERT_TRUE(map) << "no /map after the end of the playback";
  // Sized to the observed room (7.9 m x 5.9 m at 0.1 m, plus the occupied band), not to the
  // 51.2 m blocks (block_levels 9) that hold it.
  EXPECT_GE(map->info.width, 79u);
  EXPECT_LE(map->info.width, 83u);
  EXPECT_GE(map->info.height, 59u);
  EXPECT_LE(map->info.height, 63u);
  EXPECT_EQ(room::cellAt(*map, room::kUnkX, room::kUnkY), -2);  // outside the grid
  EXPECT_GT(room::cellAt(*map, room::kOccX, room::kOccY), 65);
  EXPECT_LT(room::cellAt(*map, room::kFreeX, room::kFreeY), 35);

  // One warning per input about the leading '/'.
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(3.0);
  while (ros::WallTime::now() < end) ros::WallDuration(0.1).sleep();
  std::lock_guard<std::mutex> lock(g_mutex);
  int scan_1 = 0, scan_2 = 0;
  for (const auto& w : g_slash_warnings) {
    scan_1 += w.find("/scan_1") != std::string::npos ? 1 : 0;
    scan_2 += w.find("/scan_2") != std::string::npos ? 1 : 0;
  }
  EXPECT_EQ(scan_1, 1);
  EXPECT_EQ(scan_2, 1);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_bag_end");
  ros::NodeHandle nh;
  auto status_sub = room::keepLatest<wavog_mapping::MapperStatus>(nh, "wavog_mapping/status", 10,
                                                                  &g_mutex, &g_status);
  auto map_sub = nh.subscribe<nav_msgs::OccupancyGrid>(
      "map", 2,
      boost::function<void(const nav_msgs::OccupancyGrid::ConstPtr&)>(
          [](const nav_msgs::OccupancyGrid::ConstPtr& m) {
            std::lock_guard<std::mutex> lock(g_mutex);
            g_map = m;
            g_map_receipt = ros::WallTime::now();
          }));
  auto log_sub =
      nh.subscribe<rosgraph_msgs::Log>("/rosout", 100,
                                       boost::function<void(const rosgraph_msgs::Log::ConstPtr&)>(
                                           [](const rosgraph_msgs::Log::ConstPtr& l) {
                                             if (l->msg.find("leading '/'") != std::string::npos) {
                                               std::lock_guard<std::mutex> lock(g_mutex);
                                               g_slash_warnings.push_back(l->msg);
                                             }
                                           }));
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  ros::shutdown();
  return result;
}
