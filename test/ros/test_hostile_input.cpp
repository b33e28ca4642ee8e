// Hostile input (issue 16, node side): each case is sent alone, then a good scan; the node must
// stay up, count the case under its reason, and map the good scan. Cases: time_increment 1e7,
// 1e30 and NaN, a stamp of {2^32 - 1 s, 999999999 ns}, a stamp far in the future (the next good
// scan is 2^31 s back), a /tf transform stamped 2^32 - 1 s (the tf buffer's pruning would throw:
// refused, counted in tf_refused), lasers placed by tf 2e5 m apart (a read-out of 1.6e13 cells: the
// layers are refused, not allocated, and dynamic_map fails, saying why), save_map outside map_dir
// ('..', absolute, through a symlink), and a map_file that is /dev/zero, a FIFO or a directory
// (start-up fails at once, naming it); beyond the core's limits: beams of 1e7 m and FLT_MAX with
// range_max inf, a laser 5e10 m away, a scan of 1e6 beams, clear_region of +-1e19 m. No exception
// may have been needed to survive: ~status.exceptions stays 0.
#include <gtest/gtest.h>
#include <nav_msgs/GetMap.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <std_srvs/Empty.h>
#include <sys/stat.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <limits>
#include <mutex>
#include <string>
#include <vector>

#include "room.h"
#include "run_command.h"
#include "wavog_mapping/ClearRegion.h"
#include "wavog_mapping/MapperStatus.h"
#include "wavog_mapping/SaveMap.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace {

using wavog_mapping::InputStatus;
using wavog_mapping::MapperStatus;

std::mutex g_mutex;
nav_msgs::OccupancyGrid::ConstPtr g_map;
MapperStatus::ConstPtr g_status;
ros::Publisher g_scan_pub;
ros::Publisher g_tf_pub;  ///< /tf, for a hostile transform
/// The /rosout lines about the limit of one layer.
std::vector<std::string> g_layer_logs;

void onLog(const rosgraph_msgs::Log::ConstPtr& l) {
  if (l->msg.find("limit of one layer") == std::string::npos) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  g_layer_logs.push_back(l->msg);
}

/// base_link -> far_plus / far_minus: lasers 2e5 m either side of the robot.
constexpr double kFar = 2e5;
/// base_link -> extent_plus: a laser 5e10 m away, outside the core's representable extent.
constexpr double kBeyondExtent = 5e10;

MapperStatus::ConstPtr latestStatus() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return g_status;
}

/// Waits until the status satisfies `pred`; returns the last status (may fail `pred`).
template <typename Pred>
MapperStatus::ConstPtr waitStatus(Pred pred, double timeout = 20.0) {
  return room::waitLatest(
      &g_mutex, &g_status,
      [&pred](const MapperStatus& s) { return s.inputs.size() == 1 && pred(s); }, timeout);
}

sensor_msgs::LaserScan::Ptr good() { return room::scanOf(room::sensors()[0], ros::Time::now()); }

/// Sends a good scan and waits until the node has integrated more than `integrated` scans.
MapperStatus::ConstPtr goodScanIntegrated(std::uint64_t integrated) {
  g_scan_pub.publish(good());
  return waitStatus([&](const MapperStatus& s) { return s.inputs[0].integrated > integrated; });
}

/// Sends `bad`, then a good scan; checks that `counter` of the input grew by one and that the
/// good scan was integrated (after `bad` itself when `bad_integrated`).
void sendCase(const std::string& name, const sensor_msgs::LaserScan::Ptr& bad,
              std::uint64_t InputStatus::*counter, bool bad_integrated = false) {
  SCOPED_TRACE(name);
  const auto before = latestStatus();
  ASSERT_TRUE(before);
  const std::uint64_t count = before->inputs[0].*counter;
  const std::uint64_t integrated = before->inputs[0].integrated + (bad_integrated ? 2 : 1);
  g_scan_pub.publish(bad);
  ros::WallDuration(0.1).sleep();
  g_scan_pub.publish(good());
  const auto after = waitStatus([&](const MapperStatus& s) {
    return s.inputs[0].integrated >= integrated && s.inputs[0].*counter > count;
  });
  ASSERT_TRUE(after);
  EXPECT_EQ(after->inputs[0].*counter, count + 1) << name << " not counted";
  EXPECT_GE(after->inputs[0].integrated, integrated) << "the good scan after " << name;
  EXPECT_EQ(after->exceptions, 0u);
}

class Hostile : public testing::Test {
 protected:
  void SetUp() override {
    // The node is up and mapping (and has taken these scans before the case starts).
    const auto s = latestStatus();
    const std::uint64_t integrated = s && s->inputs.size() == 1 ? s->inputs[0].integrated : 0;
    for (int i = 0; i < 3; ++i) {
      g_scan_pub.publish(good());
      ros::WallDuration(0.1).sleep();
    }
    ASSERT_TRUE(waitStatus(
        [&](const MapperStatus& st) { return st.inputs[0].integrated >= integrated + 3; }));
  }
};

TEST_F(Hostile, TimeOutOfRangeDroppedAsBadTime) {
  auto ti_1e7 = good();
  ti_1e7->time_increment = 1e7f;
  sendCase("time_increment 1e7", ti_1e7, &InputStatus::dropped_bad_time);

  auto ti_1e30 = good();
  ti_1e30->time_increment = 1e30f;
  sendCase("time_increment 1e30", ti_1e30, &InputStatus::dropped_bad_time);

  auto ti_nan = good();
  ti_nan->time_increment = std::numeric_limits<float>::quiet_NaN();
  sendCase("time_increment NaN", ti_nan, &InputStatus::dropped_bad_time);

  auto last_stamp = good();
  last_stamp->header.stamp.sec = 4294967295u;
  last_stamp->header.stamp.nsec = 999999999u;
  sendCase("stamp {4294967295, 999999999}", last_stamp, &InputStatus::dropped_bad_time);
}

TEST_F(Hostile, StampFarFromThePreviousOneCountedAsTimeJump) {
  // 4e9 s is representable (static tf places it); the next good scan is 2.2e9 s back, beyond
  // what a ros::Duration holds.
  auto future = good();
  future->header.stamp = ros::Time(4000000000u, 0);
  sendCase("stamp 4e9 s", future, &InputStatus::time_jumps, /*bad_integrated=*/true);
}

TEST_F(Hostile, TransformStampedAtTheEndOfTimeRefused) {
  // The tf buffer's pruning adds tf_cache_time to this stamp: out of ROS time, it would throw.
  const auto before = latestStatus();
  ASSERT_TRUE(before);
  room::waitForSubscribers(g_tf_pub, 1, 10.0);
  tf2_msgs::TFMessage msg;
  msg.transforms.push_back(
      room::toMsg(room::sensorInBase(room::sensors()[0]), "base_link", "late_laser"));
  msg.transforms[0].header.stamp.sec = 4294967295u;
  msg.transforms[0].header.stamp.nsec = 0;
  g_tf_pub.publish(msg);
  ros::WallDuration(0.2).sleep();
  const auto after = goodScanIntegrated(before->inputs[0].integrated);
  ASSERT_TRUE(after);
  const auto s =
      waitStatus([&](const MapperStatus& st) { return st.tf_refused > before->tf_refused; });
  ASSERT_TRUE(s);
  EXPECT_EQ(s->tf_refused, before->tf_refused + 1);
  EXPECT_EQ(s->exceptions, 0u);
}

// A map 4e5 m wide (two lasers 2e5 m either side of the robot) is beyond one layer's 2^24 cells:
// `map` and dynamic_map are the square around the robot, never the whole map, never nothing.
TEST_F(Hostile, HugeMapPublishedAsTheWindowAroundTheRobot) {
  const auto before = latestStatus();
  ASSERT_TRUE(before);
  const std::uint64_t integrated = before->inputs[0].integrated;
  for (const char* frame : {"far_plus", "far_minus"}) {
    auto scan = good();
    scan->header.frame_id = frame;
    g_scan_pub.publish(scan);
    ros::WallDuration(0.1).sleep();
  }
  auto s =
      waitStatus([&](const MapperStatus& st) { return st.inputs[0].integrated >= integrated + 2; });
  ASSERT_TRUE(s);
  const ros::Time after = ros::Time::now();
  const auto map = room::waitLatest(
      &g_mutex, &g_map, [&](const nav_msgs::OccupancyGrid& g) { return g.header.stamp > after; },
      10.0);
  ASSERT_TRUE(map);
  const double cells = static_cast<double>(map->info.width) * map->info.height;
  EXPECT_GT(cells, 0.0);
  EXPECT_LE(cells, 16777216.0) << "a map 4e5 m wide must not be published whole";
  EXPECT_LT(map->info.origin.position.x, 0.0);  // the square around the robot at the origin
  EXPECT_GT(map->info.origin.position.x + map->info.width * map->info.resolution, 0.0);
  s = latestStatus();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->layers_refused, before->layers_refused);
  EXPECT_EQ(s->exceptions, 0u);

  // dynamic_map: the same square.
  nav_msgs::GetMap get_map;
  ASSERT_TRUE(ros::service::call("dynamic_map", get_map));
  EXPECT_EQ(get_map.response.map.info.width, map->info.width);
  EXPECT_EQ(get_map.response.map.info.height, map->info.height);
  // One message says so, naming the limit and the robot's frame.
  std::vector<std::string> logs;
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(5.0);
  while (logs.empty() && ros::WallTime::now() < end) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      logs = g_layer_logs;
    }
    ros::WallDuration(0.05).sleep();
  }
  ASSERT_EQ(logs.size(), 1u);
  EXPECT_NE(logs[0].find("16777216 cells"), std::string::npos) << logs[0];
  EXPECT_NE(logs[0].find("'base_link'"), std::string::npos) << logs[0];

  // save_map: the native map is written, the images are refused (too large).
  wavog_mapping::SaveMap save;
  save.request.path = "wavog_hostile_huge_" + std::to_string(getpid()) + ".wavog";
  ASSERT_TRUE(ros::service::call("wavog_mapping/save_map", save));
  EXPECT_TRUE(save.response.success) << save.response.message;
  EXPECT_NE(save.response.message.find("no image"), std::string::npos) << save.response.message;
  for (const auto& f : save.response.files) std::remove(f.c_str());

  // After a reset the node maps again.
  std_srvs::Empty reset;
  ASSERT_TRUE(ros::service::call("wavog_mapping/reset", reset));
  s = goodScanIntegrated(s->inputs[0].integrated);
  ASSERT_TRUE(s);
  const ros::Time after_reset = ros::Time::now();
  const auto mapped = room::waitLatest(
      &g_mutex, &g_map,
      [&](const nav_msgs::OccupancyGrid& g) { return g.header.stamp > after_reset; }, 10.0);
  ASSERT_TRUE(mapped);
  EXPECT_GT(room::cellAt(*mapped, room::kOccX, room::kOccY), 65) << "the good scan is mapped";
  EXPECT_LT(mapped->info.width, 1000u);
}

/// Sends `bad`, then a good scan; both must be integrated (no hang) and `beams_no_return` grow.
void sendNoReturnCase(const std::string& name, const sensor_msgs::LaserScan::Ptr& bad) {
  SCOPED_TRACE(name);
  const auto before = latestStatus();
  ASSERT_TRUE(before);
  const std::uint64_t integrated = before->inputs[0].integrated + 2;
  const std::uint64_t no_return = before->inputs[0].beams_no_return;
  g_scan_pub.publish(bad);
  ros::WallDuration(0.1).sleep();
  g_scan_pub.publish(good());
  const auto after =
      waitStatus([&](const MapperStatus& s) { return s.inputs[0].integrated >= integrated; });
  ASSERT_TRUE(after);
  EXPECT_GE(after->inputs[0].integrated, integrated) << name << " and the good scan after it:\n"
                                                     << after->inputs[0];
  EXPECT_GT(after->inputs[0].beams_no_return, no_return) << name << ": a no-return, not a hit";
  EXPECT_EQ(after->exceptions, 0u);
}

TEST_F(Hostile, BeyondTheCoreLimitsCountedAndBounded) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  // One beam of 1e7 m, and one of FLT_MAX, with range_max +inf: beyond the hard range limit,
  // a no-return (once a hang: the block loop covered (2 x reach / block)^2 blocks).
  for (const float far : {1e7f, std::numeric_limits<float>::max()}) {
    auto scan = good();
    scan->range_max = kInf;
    scan->ranges[scan->ranges.size() / 2] = far;
    const std::uint64_t beyond_limit = latestStatus()->inputs[0].beams_beyond_limit;
    sendNoReturnCase("a beam of " + std::to_string(far) + " m, range_max inf", scan);
    EXPECT_EQ(latestStatus()->inputs[0].beams_beyond_limit, beyond_limit + 1);
  }
  // A laser placed by tf 5e10 m away: outside the extent, refused by the core and counted under
  // the reason the log names (issue 28: once counted as bad_geometry).
  auto beyond = good();
  beyond->header.frame_id = "extent_plus";
  sendCase("laser at 5e10 m", beyond, &InputStatus::dropped_out_of_extent);
  EXPECT_EQ(latestStatus()->inputs[0].dropped_bad_geometry, 0u);
  // One scan of 1e6 beams in bounded time: the work budget (2^23 beam-cells) limits its range to
  // 8 cells, so its 3 m beams are no-returns and the scan has nothing to integrate (counted).
  auto many = good();
  many->angle_min = -3.1f;
  many->angle_increment = 6.2f / 1e6f;
  many->angle_max = many->angle_min + many->angle_increment * (1e6f - 1.0f);
  many->time_increment = 0.0f;
  many->ranges.assign(1000000, 3.0f);
  many->intensities.clear();
  const std::uint64_t no_return = latestStatus()->inputs[0].beams_no_return;
  const std::uint64_t beyond_limit = latestStatus()->inputs[0].beams_beyond_limit;
  sendCase("a scan of 1e6 beams", many, &InputStatus::dropped_no_valid_beam);
  EXPECT_GE(latestStatus()->inputs[0].beams_no_return, no_return + 1000000);
  // Counted as beyond the hard range limit (issue 28: once nowhere in the status).
  EXPECT_GE(latestStatus()->inputs[0].beams_beyond_limit, beyond_limit + 1000000);
  // clear_region of +-1e19 m clears the whole map (once: an undefined cast, nothing cleared).
  wavog_mapping::ClearRegion clear;
  clear.request.min_x = clear.request.min_y = -1e19;
  clear.request.max_x = clear.request.max_y = 1e19;
  ASSERT_TRUE(ros::service::call("wavog_mapping/clear_region", clear));
  EXPECT_TRUE(clear.response.success) << clear.response.message;
  const ros::Time cleared = ros::Time::now();
  const auto empty = room::waitLatest(
      &g_mutex, &g_map, [&](const nav_msgs::OccupancyGrid& g) { return g.header.stamp > cleared; },
      10.0);
  ASSERT_TRUE(empty);
  for (const std::int8_t v : empty->data) ASSERT_EQ(v, -1) << "a cell survived clear_region";
  const auto s = goodScanIntegrated(latestStatus()->inputs[0].integrated);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->exceptions, 0u);
}

TEST_F(Hostile, SaveMapOnlyBelowMapDir) {
  const std::string pid = std::to_string(getpid());
  const std::string link = "/tmp/wavog_hostile_link_" + pid;
  ASSERT_EQ(::symlink("/etc", link.c_str()), 0);
  for (const std::string& path :
       {std::string("../wavog_hostile_") + pid + ".wavog", "/etc/wavog_hostile_" + pid + ".wavog",
        "wavog_hostile_link_" + pid + "/x.wavog", std::string("/tmp")}) {
    SCOPED_TRACE(path);
    wavog_mapping::SaveMap save;
    save.request.path = path;
    ASSERT_TRUE(ros::service::call("wavog_mapping/save_map", save));
    EXPECT_FALSE(save.response.success);
    EXPECT_NE(save.response.message.find("refused"), std::string::npos) << save.response.message;
    EXPECT_TRUE(save.response.files.empty());
  }
  ::unlink(link.c_str());
  // A relative name resolves below map_dir (/tmp). Symlinks planted at the names of the
  // map_server files beside it are replaced, never written through.
  const std::string victim = "/tmp/wavog_hostile_victim_" + pid;
  std::ofstream(victim) << "victim\n";
  const std::string stem = "/tmp/wavog_hostile_" + pid;
  for (const std::string name : {stem + "_s0.pgm", stem + "_s0.yaml", stem + "_s2.pgm"}) {
    ASSERT_EQ(::symlink(victim.c_str(), name.c_str()), 0) << name;
  }
  wavog_mapping::SaveMap save;
  save.request.path = "wavog_hostile_" + pid + ".wavog";
  ASSERT_TRUE(ros::service::call("wavog_mapping/save_map", save));
  ASSERT_TRUE(save.response.success) << save.response.message;
  ASSERT_FALSE(save.response.files.empty());
  EXPECT_EQ(save.response.files[0], "/tmp/wavog_hostile_" + pid + ".wavog");
  struct stat st {};
  EXPECT_EQ(::stat(save.response.files[0].c_str(), &st), 0);
  std::ifstream in(victim);
  const std::string victim_now((std::istreambuf_iterator<char>(in)),
                               std::istreambuf_iterator<char>());
  EXPECT_EQ(victim_now, "victim\n") << "save_map wrote through a symlink";
  const auto& files = save.response.files;
  ASSERT_NE(std::find(files.begin(), files.end(), stem + "_s0.pgm"), files.end());
  for (const std::string name : {stem + "_s0.pgm", stem + "_s0.yaml", stem + "_s2.pgm"}) {
    if (std::find(files.begin(), files.end(), name) != files.end()) {
      EXPECT_EQ(::lstat(name.c_str(), &st), 0) << name;
      EXPECT_TRUE(S_ISREG(st.st_mode)) << name << " is still a symlink";
    }
    std::remove(name.c_str());
  }
  for (const auto& f : save.response.files) std::remove(f.c_str());
  std::remove(victim.c_str());
}

TEST(HostileStartUp, MapFileNotARegularFileFailsAtOnce) {
  const std::string pid = std::to_string(getpid());
  const std::string fifo = "/tmp/wavog_hostile_fifo_" + pid;
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string& file : {std::string("/dev/zero"), fifo, std::string("/tmp")}) {
    SCOPED_TRACE(file);
    std::string output;
    const ros::WallTime t0 = ros::WallTime::now();
    // timeout: a node blocked on the FIFO would exit 124, not 1.
    const int code = room::run(std::string("timeout 20 ") + WAVOG_NODE_BIN + " __name:=hostile_" +
                                   pid + " map:=/hostile_" + pid + "/map _map_file:=" + file,
                               &output);
    EXPECT_EQ(code, 1) << output;
    EXPECT_NE(output.find("map_file"), std::string::npos) << output;
    EXPECT_NE(output.find(file), std::string::npos) << output;
    EXPECT_NE(output.find("regular file"), std::string::npos) << output;
    EXPECT_LT((ros::WallTime::now() - t0).toSec(), 15.0);
  }
  ::unlink(fifo.c_str());
}

TEST(HostileStartUp, MapFileWithPayloadsTheNodeDropsIsWarnedAbout) {
  // A map with a reflection map and NDT cells, loaded by a node configured without either.
  const std::string pid = std::to_string(getpid());
  const std::string file = "/tmp/wavog_hostile_payloads_" + pid + ".wavog";
  {
    wavog::MapParams p = wavog::MapParams::defaultsFor(wavog::PolicyType::kForget);
    p.reflection = p.ndt = true;
    wavog::WaveletMap map(p);
    std::vector<float> ranges(90, 2.0f);
    wavog::ScanView scan;
    scan.ranges = ranges.data();
    scan.count = ranges.size();
    scan.angle_min = -0.8f;
    scan.angle_increment = 0.02f;
    scan.range_min = 0.1f;
    scan.range_max = 10.0f;
    map.integrate(wavog::Pose2{0.0, 0.0, 0.0}, scan);
    map.save(file);
  }
  std::string output;
  // The node keeps running after start-up: `timeout` ends it (exit 124) once it has said so.
  const int code = room::run(std::string("timeout 6 ") + WAVOG_NODE_BIN + " __name:=payloads_" +
                                 pid + " map:=/payloads_" + pid + "/map map_metadata:=/payloads_" +
                                 pid + "/map_metadata dynamic_map:=/payloads_" + pid +
                                 "/dynamic_map _map_file:=" + file,
                             &output);
  EXPECT_EQ(code, 124) << output;
  EXPECT_NE(output.find("holds a reflection map, which this mapper drops (reflection: false)"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("holds normal-distribution (NDT) cells, which this mapper drops (ndt: "
                        "false)"),
            std::string::npos)
      << output;
  std::remove(file.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_hostile_input");
  ros::NodeHandle nh;
  tf2_ros::StaticTransformBroadcaster static_tf;
  auto tree = room::staticTree();
  for (const double x : {kFar, -kFar}) {
    tf2::Transform t(tf2::Quaternion::getIdentity(), tf2::Vector3(x, 0.0, 0.0));
    tree.push_back(room::toMsg(t, "base_link", x > 0 ? "far_plus" : "far_minus"));
  }
  tree.push_back(room::toMsg(
      tf2::Transform(tf2::Quaternion::getIdentity(), tf2::Vector3(kBeyondExtent, 0.0, 0.0)),
      "base_link", "extent_plus"));
  static_tf.sendTransform(tree);
  g_scan_pub = nh.advertise<sensor_msgs::LaserScan>("scan_1", 50);
  g_tf_pub = nh.advertise<tf2_msgs::TFMessage>("/tf", 10);
  auto map_sub = room::keepLatest<nav_msgs::OccupancyGrid>(nh, "map", 2, &g_mutex, &g_map);
  auto status_sub =
      room::keepLatest<MapperStatus>(nh, "wavog_mapping/status", 10, &g_mutex, &g_status);
  auto log_sub = nh.subscribe("/rosout", 100, onLog);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  room::waitForSubscribers(g_scan_pub, 1, 20.0);
  return RUN_ALL_TESTS();
}
