// wavog_simulate end to end: the bag holds one LaserScan topic per laser with the simulator's
// ranges bit for bit (so a seed fixes the bag), monotonic stamps, /tf at every scan and a latched
// /tf_static with the mounts; and wavog_offline maps it unchanged (when it is built).
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "wavog_mapping/sim/laser_sim.h"
#include "wavog_mapping/sim/world.h"

namespace wavog {
namespace sim {
namespace {

constexpr double kDuration = 1.0;  // s: 160 scans
constexpr std::uint64_t kSeed = 42;
constexpr double kEpoch = 1.7e9;  // bag time of scenario time 0 (wavog_simulate)

std::string tempDir() {
  char pattern[] = "/tmp/wavog_sim_bag_XXXXXX";
  const char* dir = mkdtemp(pattern);
  return dir ? dir : "/tmp";
}

TEST(SimulateBag, HoldsTheSimulatedScansAndTheTfTree) {
  const std::string dir = tempDir();
  const std::string bag_path = dir + "/scenario.bag";
  std::ostringstream cmd;
  cmd << WAVOG_SIMULATE << " --seed " << kSeed << " --duration " << kDuration << " --out "
      << bag_path << " 2>/dev/null";
  ASSERT_EQ(std::system(cmd.str().c_str()), 0) << cmd.str();

  const World world = defaultWorld(kDuration);
  const ScanSimulator sim(world, kSeed);
  std::map<std::string, int> laser_of_topic;
  for (std::size_t i = 0; i < world.vehicle.lasers.size(); ++i) {
    laser_of_topic["/" + world.vehicle.lasers[i].topic] = static_cast<int>(i);
  }

  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  std::map<std::string, std::uint64_t> scans;
  std::size_t tf_messages = 0, tf_static = 0;
  ros::Time last;
  for (const rosbag::MessageInstance& m : view) {
    EXPECT_GE(m.getTime(), last);
    last = m.getTime();
    if (m.getTopic() == "/tf_static") {
      ++tf_static;
      EXPECT_EQ(m.getConnectionHeader()->at("latching"), "1");
      const auto msg = m.instantiate<tf2_msgs::TFMessage>();
      ASSERT_TRUE(msg);
      ASSERT_EQ(msg->transforms.size(), 4u);
      EXPECT_EQ(msg->transforms[0].header.frame_id, "base_link");
      EXPECT_EQ(msg->transforms[0].child_frame_id, "laser_front_left");
      EXPECT_NEAR(msg->transforms[0].transform.translation.x, 4.0, 1e-12);
    } else if (m.getTopic() == "/tf") {
      ++tf_messages;
      const auto msg = m.instantiate<tf2_msgs::TFMessage>();
      ASSERT_TRUE(msg);
      EXPECT_EQ(msg->transforms.at(0).header.frame_id, "map");
      EXPECT_EQ(msg->transforms.at(0).child_frame_id, "base_link");
    } else {
      ASSERT_TRUE(laser_of_topic.count(m.getTopic())) << m.getTopic();
      const int laser = laser_of_topic[m.getTopic()];
      const auto msg = m.instantiate<sensor_msgs::LaserScan>();
      ASSERT_TRUE(msg);
      const std::uint64_t seq = scans[m.getTopic()]++;
      const SimScan expected = sim.simulate(laser, seq);
      EXPECT_EQ(msg->header.frame_id,
                world.vehicle.lasers[static_cast<std::size_t>(laser)].frame_id);
      EXPECT_NEAR(msg->header.stamp.toSec() - kEpoch, expected.stamp, 1e-6);
      ASSERT_EQ(msg->ranges.size(), expected.ranges.size());
      EXPECT_EQ(std::memcmp(msg->ranges.data(), expected.ranges.data(),
                            expected.ranges.size() * sizeof(float)),
                0);
      EXPECT_NEAR(msg->angle_increment, M_PI / 360, 1e-7);
      EXPECT_EQ(msg->range_max, 80.0f);
    }
  }
  EXPECT_EQ(tf_static, 1u);
  EXPECT_EQ(tf_messages, 161u);  // one per scan plus one at the end
  ASSERT_EQ(scans.size(), 4u);
  for (const auto& [topic, n] : scans) EXPECT_EQ(n, 40u) << topic;
  bag.close();

#ifdef WAVOG_OFFLINE
  std::ostringstream offline;
  offline << WAVOG_OFFLINE << " --quiet --config " << WAVOG_SOURCE_DIR << "/config/default.yaml"
          << " --topics scan_front_left,scan_front_right,scan_rear_left,scan_rear_right"
          << " --scale 0 --out " << dir << "/map " << bag_path;
  ASSERT_EQ(std::system(offline.str().c_str()), 0) << offline.str();
  std::ifstream in(dir + "/map/summary.json");
  std::stringstream summary;
  summary << in.rdbuf();
  EXPECT_NE(summary.str().find("\"scans_integrated\": 160"), std::string::npos) << summary.str();
  EXPECT_NE(summary.str().find("\"scans_dropped\": 0"), std::string::npos) << summary.str();
#endif
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sim
}  // namespace wavog
