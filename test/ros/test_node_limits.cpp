// The node's limits without a roscore (issue 16): ROS time arithmetic checked before it can throw
// (secondsBetween, addSeconds, checkScanTime, tfStampUsable), the publication sizing (layerBox,
// kMaxLayerCells) and where ~save_map may write (resolveSavePath below map_dir).
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "../../src/ros/save_path.h"
#include "fan_scan.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/ros/conversions.h"

namespace {

using wavog_ros::addSeconds;
using wavog_ros::checkScanTime;
using wavog_ros::DropReason;
using wavog_ros::LayerSize;

ros::Time stampOf(std::uint32_t sec, std::uint32_t nsec) {
  ros::Time t;  // as deserialised: not normalised
  t.sec = sec;
  t.nsec = nsec;
  return t;
}

sensor_msgs::LaserScan scanOf(std::size_t beams, float time_increment, const ros::Time& stamp) {
  sensor_msgs::LaserScan s;
  s.header.frame_id = "laser";
  s.header.stamp = stamp;
  s.angle_min = -1.0f;
  s.angle_increment = 0.01f;
  s.angle_max = s.angle_min + s.angle_increment * static_cast<float>(beams - 1);
  s.time_increment = time_increment;
  s.range_min = 0.1f;
  s.range_max = 30.0f;
  s.ranges.assign(beams, 5.0f);
  return s;
}

TEST(NodeTime, SecondsBetweenNeverThrows) {
  EXPECT_DOUBLE_EQ(wavog_ros::secondsBetween(stampOf(10, 500000000), stampOf(8, 0)), 2.5);
  // ros::Time's operator- throws here (more than 2^31 s apart).
  const double d = wavog_ros::secondsBetween(stampOf(4294967295u, 999999999u), stampOf(0, 0));
  EXPECT_NEAR(d, 4294967296.0, 1e-3);
  EXPECT_LT(wavog_ros::secondsBetween(stampOf(0, 0), stampOf(4294967295u, 0)), -4e9);
}

TEST(NodeTime, AddSecondsRefusesWhatRosTimeCannotHold) {
  ros::Time out;
  ASSERT_TRUE(addSeconds(stampOf(100, 0), 0.25, &out));
  EXPECT_EQ(out, ros::Time(100, 250000000));
  ASSERT_TRUE(addSeconds(stampOf(100, 0), -50.0, &out));
  EXPECT_EQ(out, ros::Time(50, 0));
  ASSERT_TRUE(addSeconds(stampOf(1, 0), 3e9, &out));  // longer than a ros::Duration holds
  EXPECT_NEAR(out.toSec(), 3e9 + 1.0, 1e-3);
  const ros::Time last = stampOf(4294967295u, 999999999u);
  EXPECT_FALSE(addSeconds(last, 0.03, &out));
  EXPECT_FALSE(addSeconds(stampOf(10, 0), -11.0, &out));
  EXPECT_FALSE(addSeconds(stampOf(10, 0), std::numeric_limits<double>::quiet_NaN(), &out));
  EXPECT_FALSE(addSeconds(stampOf(10, 0), std::numeric_limits<double>::infinity(), &out));
  EXPECT_FALSE(addSeconds(stampOf(10, 0), 1e30, &out));
}

TEST(NodeTime, CheckScanTime) {
  const ros::Time now = stampOf(1700000000u, 0);
  DropReason reason = DropReason::kEmpty;
  EXPECT_TRUE(checkScanTime(scanOf(361, 7.4e-5f, now), 0.03, &reason));
  EXPECT_TRUE(checkScanTime(scanOf(361, -7.4e-5f, now), 0.03, &reason));  // reversed sweep
  EXPECT_TRUE(checkScanTime(scanOf(361, 0.0f, now), 0.03, &reason));
  EXPECT_TRUE(checkScanTime(scanOf(1, 1e7f, now), 0.03, &reason));  // one beam: no sweep
  for (const float ti : {1e7f, 1e30f, -1e7f, 0.1f, std::numeric_limits<float>::quiet_NaN(),
                         std::numeric_limits<float>::infinity()}) {
    reason = DropReason::kEmpty;
    EXPECT_FALSE(checkScanTime(scanOf(361, ti, now), 0.03, &reason)) << ti;
    EXPECT_EQ(reason, DropReason::kBadTime) << ti;
  }
  reason = DropReason::kEmpty;
  EXPECT_FALSE(checkScanTime(scanOf(361, 0.0f, stampOf(4294967295u, 999999999u)), 0.03, &reason));
  EXPECT_EQ(reason, DropReason::kBadTime);
  // The sweep ends before time 0.
  EXPECT_FALSE(checkScanTime(scanOf(361, -1e-2f, stampOf(1, 0)), 0.0, &reason));
}

TEST(NodeTime, TfStampUsable) {
  EXPECT_TRUE(wavog_ros::tfStampUsable(stampOf(0, 0), 30.0));
  EXPECT_TRUE(wavog_ros::tfStampUsable(stampOf(1700000000u, 0), 3600.0));
  EXPECT_FALSE(wavog_ros::tfStampUsable(stampOf(4294967295u, 0), 10.0));
  EXPECT_FALSE(wavog_ros::tfStampUsable(stampOf(4294967290u, 0), 10.0));
}

wavog::MapParams smallParams() {
  wavog::MapParams p = wavog::MapParams::defaultsFor(wavog::PolicyType::kForget);
  p.grid.resolution = 0.1;
  p.grid.block_levels = 4;
  return p;
}

using fan_scan::scanAt;

TEST(LayerBox, EmptyMapWholeMapAndWindow) {
  wavog::WaveletMap map(smallParams());
  wavog::CellBox box;
  EXPECT_EQ(wavog_ros::layerBox(map, 0, 0.0, 0, 0, &box), LayerSize::kEmpty);
  EXPECT_EQ(wavog_ros::layerBox(map, 0, 10.0, 0, 0, &box), LayerSize::kEmpty);
  scanAt(&map, 0.0, 0.0);
  wavog::CellBox bounds;
  ASSERT_TRUE(map.bounds(0, &bounds));
  ASSERT_EQ(wavog_ros::layerBox(map, 0, 0.0, 0, 0, &box), LayerSize::kOk);
  EXPECT_EQ(box.min_x, bounds.min_x);
  EXPECT_EQ(box.max_y, bounds.max_y);
  // A window around the robot on the map: the whole window, as before (unknown around the map).
  ASSERT_EQ(wavog_ros::layerBox(map, 0, 10.0, 0.0, 0.0, &box), LayerSize::kOk);
  EXPECT_EQ(box.width(), map.boxAround(-10, -10, 10, 10, 0).width());
  EXPECT_EQ(box.min_x, map.boxAround(-10, -10, 10, 10, 0).min_x);
  // A centre far off the map or not finite: nothing to publish (and no float-to-int overflow).
  EXPECT_EQ(wavog_ros::layerBox(map, 0, 10.0, 1e30, 0.0, &box), LayerSize::kEmpty);
  EXPECT_EQ(wavog_ros::layerBox(map, 0, 10.0, std::nan(""), 0.0, &box), LayerSize::kEmpty);
  // A window of 1e300 m: clipped to the bounds.
  ASSERT_EQ(wavog_ros::layerBox(map, 0, 1e300, 0.0, 0.0, &box), LayerSize::kOk);
  EXPECT_LE(box.width(), bounds.width() + 1);
  EXPECT_LE(box.height(), bounds.height() + 1);
}

TEST(LayerBox, HugeMapRefusedUnlessWindowed) {
  wavog::WaveletMap map(smallParams());
  scanAt(&map, -2e5, 0.0);
  scanAt(&map, 2e5, 0.0);
  wavog::CellBox box;
  EXPECT_EQ(wavog_ros::layerBox(map, 0, 0.0, 0, 0, &box), LayerSize::kTooLarge);
  EXPECT_GT(static_cast<double>(box.width()) * static_cast<double>(box.height()),
            wavog_ros::kMaxLayerCells);
  // A window around one of the rooms is small: published.
  ASSERT_EQ(wavog_ros::layerBox(map, 0, 20.0, 2e5, 0.0, &box), LayerSize::kOk);
  EXPECT_LE(static_cast<double>(box.width()) * static_cast<double>(box.height()),
            wavog_ros::kMaxLayerCells);
}

class SavePath : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("wavog_save_path_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_ / "sub");
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(SavePath, RelativeAndAbsoluteBelowMapDir) {
  std::string resolved, error;
  ASSERT_TRUE(wavog_ros::resolveSavePath(dir_.string(), "map.wavog", &resolved, &error)) << error;
  EXPECT_EQ(resolved, (dir_ / "map.wavog").string());
  ASSERT_TRUE(wavog_ros::resolveSavePath(dir_.string(), "sub/./map.wavog", &resolved, &error));
  EXPECT_EQ(resolved, (dir_ / "sub" / "map.wavog").string());
  ASSERT_TRUE(wavog_ros::resolveSavePath(dir_.string() + "/", (dir_ / "sub/m.wavog").string(),
                                         &resolved, &error))
      << error;
  // A directory that does not exist yet below map_dir is fine (the save says if it fails).
  ASSERT_TRUE(wavog_ros::resolveSavePath(dir_.string(), "new/dir/m.wavog", &resolved, &error));
}

// Issue 41, item 9: an absolute path inside map_dir is accepted also where map_dir or the path
// goes through a symlink; a relative map_dir (a relative $ROS_HOME) still gives an absolute file.
TEST_F(SavePath, AbsolutePathsInsideMapDirThroughSymlinks) {
  std::filesystem::create_directories(dir_ / "real");
  ASSERT_EQ(::symlink((dir_ / "real").c_str(), (dir_ / "alias").c_str()), 0);
  std::string resolved, error;
  EXPECT_TRUE(wavog_ros::resolveSavePath((dir_ / "alias").string(),
                                         (dir_ / "real" / "m.wavog").string(), &resolved, &error))
      << error;
  EXPECT_EQ(resolved, (dir_ / "real" / "m.wavog").string());
  EXPECT_TRUE(wavog_ros::resolveSavePath(
      (dir_ / "real").string(), (dir_ / "alias" / "sub" / "m.wavog").string(), &resolved, &error))
      << error;
  EXPECT_EQ(resolved, (dir_ / "alias" / "sub" / "m.wavog").string());
  // Still refused: the folder itself, and beside it.
  EXPECT_FALSE(wavog_ros::resolveSavePath((dir_ / "alias").string(), (dir_ / "real").string(),
                                          &resolved, &error));
  EXPECT_FALSE(wavog_ros::resolveSavePath((dir_ / "alias").string(), (dir_ / "m.wavog").string(),
                                          &resolved, &error));
  EXPECT_NE(error.find("not a file below map_dir '" + (dir_ / "alias").string() + "'"),
            std::string::npos)
      << error;

  const std::filesystem::path cwd = std::filesystem::current_path();
  std::filesystem::current_path(dir_);
  const bool ok = wavog_ros::resolveSavePath("rel", "saved/m.wavog", &resolved, &error);
  std::filesystem::current_path(cwd);
  ASSERT_TRUE(ok) << error;
  EXPECT_EQ(resolved, (dir_ / "rel" / "saved" / "m.wavog").string());

  // The answer names the folder the files went to.
  EXPECT_EQ(
      wavog_ros::savedMessage({"/root/.ros/saved/robot.wavog", "/root/.ros/saved/robot_s0.pgm"}),
      "saved 2 files in /root/.ros/saved: robot.wavog robot_s0.pgm");
  EXPECT_EQ(wavog_ros::savedMessage({"/tmp/m.wavog"}), "saved 1 file in /tmp: m.wavog");
}

TEST_F(SavePath, RefusedOutsideMapDir) {
  ASSERT_EQ(::symlink("/etc", (dir_ / "escape").c_str()), 0);
  const std::string prefix = dir_.string() + "_other/m.wavog";  // shares the prefix text only
  for (const std::string& path :
       {std::string(""), std::string("../m.wavog"), std::string("sub/../../m.wavog"),
        std::string("/etc/m.wavog"), prefix, dir_.string(), std::string("escape/passwd"),
        std::string(".")}) {
    std::string resolved = "unchanged", error;
    EXPECT_FALSE(wavog_ros::resolveSavePath(dir_.string(), path, &resolved, &error)) << path;
    EXPECT_FALSE(error.empty()) << path;
    EXPECT_EQ(resolved, "unchanged") << path;
  }
}

}  // namespace
