// Real-bag rostest (real_bag.test): a bag this project did not write, with '/'-prefixed frame ids
// and no tf, played through playback.launch with fixed_frame_laser:=true. Every scan of the bag
// must be received and integrated (none dropped for its frame, none left waiting for tf at the
// end), and /map must hold occupied and free cells within the observed bounds (the robot moves
// while the laser is held fixed, so the map is smeared: this checks the plumbing, not the map).
#include <gtest/gtest.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>

#include <cstdint>
#include <string>

#include "mapper_listener.h"
#include "wavog_mapping/MapperStatus.h"

namespace {

constexpr double kWaitSeconds = 90.0;   // wall time for the bag (36 s at 4x) and the end flush
constexpr int kOccupied = 65;           // map_server's occupied threshold (0..100)
constexpr int kFree = 25;               // and its free threshold

struct BagFacts {
  std::uint64_t scans = 0;
  std::uint64_t slashed = 0;  // scans whose frame_id starts with '/'
  std::uint64_t tf = 0;       // messages on /tf or /tf_static
};

BagFacts readBag(const std::string& path) {
  BagFacts f;
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  for (const rosbag::MessageInstance& m : view) {
    if (m.getTopic() == "/tf" || m.getTopic() == "/tf_static") ++f.tf;
    const sensor_msgs::LaserScan::ConstPtr scan = m.instantiate<sensor_msgs::LaserScan>();
    if (!scan) continue;
    ++f.scans;
    if (!scan->header.frame_id.empty() && scan->header.frame_id[0] == '/') ++f.slashed;
  }
  return f;
}

TEST(RealBag, EveryScanOfASlashFrameBagWithoutTfIsMapped) {
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  std::string path;
  ASSERT_TRUE(pnh.getParam("bag", path));
  const BagFacts bag = readBag(path);
  // What makes this bag hard: check it still is that bag.
  ASSERT_GT(bag.scans, 100u);
  ASSERT_EQ(bag.slashed, bag.scans);
  ASSERT_EQ(bag.tf, 0u);

  const wavog_test::MapperListener mapper(nh);
  ros::AsyncSpinner spinner(1);
  spinner.start();

  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kWaitSeconds);
  wavog_mapping::InputStatus input;
  while (ros::ok() && ros::WallTime::now() < deadline) {
    mapper.firstInput(&input);
    if (input.integrated >= bag.scans) break;
    ros::WallDuration(0.1).sleep();
  }
  EXPECT_EQ(input.received, bag.scans) << input;
  EXPECT_EQ(input.integrated, bag.scans) << input;
  EXPECT_EQ(input.dropped_bad_frame, 0u) << input;
  EXPECT_EQ(input.dropped_tf_unavailable, 0u) << input;

  // The last publication after the end of the bag carries every scan: wait for a /map newer
  // than the last integration.
  nav_msgs::OccupancyGrid::ConstPtr map;
  const ros::WallTime map_deadline = ros::WallTime::now() + ros::WallDuration(20.0);
  while (ros::ok() && ros::WallTime::now() < map_deadline) {
    map = mapper.map();
    if (map && map->header.stamp >= input.last_stamp) break;
    ros::WallDuration(0.1).sleep();
  }
  ASSERT_TRUE(map != nullptr) << "no /map received";
  std::uint64_t occupied = 0;
  std::uint64_t free = 0;
  for (const std::int8_t v : map->data) {
    if (v >= kOccupied) ++occupied;
    if (v >= 0 && v <= kFree) ++free;
  }
  EXPECT_GT(occupied, 200u) << "walls of the room";
  // The robot moves through the bag while its laser is held fixed, so walls smear: only ask for
  // free space in front of the laser, not for a clean room.
  EXPECT_GT(free, 1000u) << "free space in front of the laser";
  // The layer covers what the laser saw (a room of some metres), not whole 1024-cell blocks.
  const double width_m = map->info.width * map->info.resolution;
  const double height_m = map->info.height * map->info.resolution;
  EXPECT_LT(width_m, 40.0);
  EXPECT_LT(height_m, 40.0);
  EXPECT_LT(map->info.width, 1024u);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_real_bag");
  return RUN_ALL_TESTS();
}
