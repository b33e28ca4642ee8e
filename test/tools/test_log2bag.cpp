// Tests of wavog_log2bag, run as a program: the first 300 scans of fr079 (FLASER, relative stamps)
// and of csail (ROBOTLASER1, absolute stamps) converted and read back with the rosbag API (topics,
// counts, types, seq from 1, strictly increasing stamps, frames, REP 117 ranges, tf composing to the logged
// laser pose); malformed lines (lenient and --strict); a truncated .gz; time stamp repairs.
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "program_runner.h"
#include "synthetic_log.h"
#include "tool_support.h"
#include "wavog_mapping/io/carmen_reader.h"

namespace {

namespace fs = std::filesystem;

using wavog_tool_test::dataFile;
using wavog_tool_test::RunResult;

fs::path workDir() {
  static const fs::path dir = wavog_tool_test::freshDir("wavog_log2bag_test");
  return dir;
}

RunResult runLog2Bag(const std::string& args) {
  return wavog_tool_test::runProgram(WAVOG_LOG2BAG, args, workDir());
}

/// Every message of a bag, by topic, with the connection headers.
struct BagContent {
  std::map<std::string, std::size_t> counts;
  std::map<std::string, std::string> types;
  std::map<std::string, std::string> latching;
  std::vector<sensor_msgs::LaserScan> scans;
  std::vector<ros::Time> scan_bag_times;
  std::vector<geometry_msgs::TransformStamped> tf;
  std::vector<geometry_msgs::TransformStamped> tf_static;
};

BagContent readBag(const std::string& path) {
  BagContent c;
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  for (const rosbag::ConnectionInfo* info : view.getConnections()) {
    c.types[info->topic] = info->datatype;
    const auto it = info->header->find("latching");
    c.latching[info->topic] = it == info->header->end() ? "" : it->second;
  }
  for (const rosbag::MessageInstance& m : view) {
    ++c.counts[m.getTopic()];
    if (auto scan = m.instantiate<sensor_msgs::LaserScan>()) {
      c.scans.push_back(*scan);
      c.scan_bag_times.push_back(m.getTime());
    } else if (auto tf = m.instantiate<tf2_msgs::TFMessage>()) {
      auto& out = m.getTopic() == "/tf_static" ? c.tf_static : c.tf;
      out.insert(out.end(), tf->transforms.begin(), tf->transforms.end());
    }
  }
  return c;
}

wavog::Pose2 toPose(const geometry_msgs::Transform& t) {
  return {t.translation.x, t.translation.y, 2.0 * std::atan2(t.rotation.z, t.rotation.w)};
}

/// Checks one converted log against the scans read directly from it.
void checkConversion(const std::string& log, const BagContent& c, std::size_t n) {
  const std::vector<wavog::CarmenScan> direct = wavog::readCarmenLog(log, n);
  ASSERT_EQ(direct.size(), n);
  EXPECT_EQ(c.counts.size(), 3u);
  EXPECT_EQ(c.counts.at("/front_laser/scan"), n);
  EXPECT_EQ(c.counts.at("/tf"), n);
  EXPECT_EQ(c.counts.at("/tf_static"), 1u);
  EXPECT_EQ(c.types.at("/front_laser/scan"), "sensor_msgs/LaserScan");
  EXPECT_EQ(c.types.at("/tf"), "tf2_msgs/TFMessage");
  EXPECT_EQ(c.latching.at("/tf_static"), "1");
  ASSERT_EQ(c.tf_static.size(), 1u);
  EXPECT_EQ(c.tf_static[0].header.frame_id, "base_link");
  EXPECT_EQ(c.tf_static[0].child_frame_id, "front_laser");
  const wavog::Pose2 mount = toPose(c.tf_static[0].transform);
  ASSERT_EQ(c.scans.size(), n);
  ASSERT_EQ(c.tf.size(), n);
  std::size_t inf_count = 0;
  std::size_t sentinel_count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const sensor_msgs::LaserScan& s = c.scans[i];
    EXPECT_EQ(s.header.frame_id, "front_laser");
    EXPECT_EQ(s.header.seq, i + 1) << "numbered from 1, so that a node counts scans it never got";
    EXPECT_EQ(s.header.stamp, c.scan_bag_times[i]);
    if (i > 0) {
      EXPECT_GT(s.header.stamp, c.scans[i - 1].header.stamp) << "scan " << i;
    }
    EXPECT_EQ(c.tf[i].header.stamp, s.header.stamp);
    EXPECT_EQ(c.tf[i].header.frame_id, "map");
    EXPECT_EQ(c.tf[i].child_frame_id, "base_link");
    ASSERT_EQ(s.ranges.size(), direct[i].ranges.size());
    EXPECT_FLOAT_EQ(s.angle_min, static_cast<float>(direct[i].angle_min));
    EXPECT_FLOAT_EQ(s.angle_increment, static_cast<float>(direct[i].angle_increment));
    EXPECT_NEAR(s.angle_max, s.angle_min + s.angle_increment * (s.ranges.size() - 1.0), 1e-5);
    EXPECT_FLOAT_EQ(s.range_max, static_cast<float>(direct[i].range_max));
    for (std::size_t k = 0; k < s.ranges.size(); ++k) {
      if (direct[i].isNoReturn(direct[i].ranges[k])) {
        ++sentinel_count;
        inf_count += std::isinf(s.ranges[k]) && s.ranges[k] > 0 ? 1 : 0;
      } else {
        EXPECT_EQ(s.ranges[k], direct[i].ranges[k]);
      }
    }
    // map -> base_link -> laser is the logged laser pose.
    const wavog::Pose2 laser = wavog_tools::compose(toPose(c.tf[i].transform), mount);
    EXPECT_NEAR(laser.x, direct[i].laser_pose.x, 1e-9);
    EXPECT_NEAR(laser.y, direct[i].laser_pose.y, 1e-9);
    EXPECT_NEAR(wavog_tools::wrapAngle(laser.theta - direct[i].laser_pose.theta), 0.0, 1e-9);
  }
  EXPECT_GT(sentinel_count, 0u);
  EXPECT_EQ(inf_count, sentinel_count);
}

TEST(Log2Bag, RealDataFr079First300Scans) {
  const std::string log = dataFile("fr079-corrected.log.gz");
  ASSERT_FALSE(log.empty()) << "shared data not found: set WAVOG_DATA_DIR";
  const std::string bag = (workDir() / "fr079_300.bag").string();
  const RunResult r = runLog2Bag("--max-scans 300 " + log + " " + bag);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("300 relative time stamps shifted by 1600000000 s"), std::string::npos)
      << r.err;
  const BagContent c = readBag(bag);
  checkConversion(log, c, 300);
  // Relative stamps start at the epoch, with the logged microseconds.
  EXPECT_EQ(c.scans[0].header.stamp, ros::Time(1600000000, 227623000));
}

TEST(Log2Bag, RealDataCsailFirst300ScansKeepAbsoluteStamps) {
  const std::string log = dataFile("csail-robotlaser1.log.gz");
  ASSERT_FALSE(log.empty()) << "shared data not found: set WAVOG_DATA_DIR";
  const std::string bag = (workDir() / "csail_300.bag").string();
  const RunResult r = runLog2Bag("--max-scans 300 --compression lz4 " + log + " " + bag);
  ASSERT_EQ(r.status, 0) << r.err;
  const BagContent c = readBag(bag);
  checkConversion(log, c, 300);
  EXPECT_EQ(c.scans[0].header.stamp, ros::Time(1134864642, 914187000));
  EXPECT_EQ(r.err.find("shifted"), std::string::npos) << r.err;
}

std::string flaser(double t, const std::string& first_range = "2.0") {
  std::string line = "FLASER 180 " + first_range;
  for (int i = 1; i < 180; ++i) line += " 2.0";
  return line + " 1 2 0.5 1 2 0.5 " + std::to_string(t) + " host " + std::to_string(t);
}

std::string writeLog(const std::string& name, const std::vector<std::string>& lines) {
  const std::string path = (workDir() / name).string();
  std::ofstream out(path);
  for (const auto& l : lines) out << l << "\n";
  return path;
}

TEST(Log2Bag, MalformedLineIsReportedAndSkippedOrFatalWithStrict) {
  const std::string log =
      writeLog("bad.log", {flaser(1.0), flaser(1.1, "x"), "FLASER 3 1", flaser(1.2)});
  const std::string bag = (workDir() / "bad.bag").string();
  RunResult r = runLog2Bag(log + " " + bag);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find(log + ":2: FLASER: field 'range' is not a number: 'x'"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(log + ":3: FLASER: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("2 malformed line(s) skipped"), std::string::npos) << r.err;
  EXPECT_EQ(readBag(bag).counts.at("/front_laser/scan"), 2u);

  const std::string strict_bag = (workDir() / "strict.bag").string();
  r = runLog2Bag("--strict " + log + " " + strict_bag);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find(log + ":2: FLASER: field 'range' is not a number"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(strict_bag));
}

TEST(Log2Bag, TruncatedGzipIsAnErrorAndKeepsTheScansBeforeIt) {
  const std::string whole = wavog_test::gzipDeflate(wavog_test::syntheticFlaserLog(400));
  const std::string bytes = whole.substr(0, whole.size() / 2);  // about 200 scans
  const std::string cut = (workDir() / "cut.log.gz").string();
  std::ofstream(cut, std::ios::binary) << bytes;
  const std::string bag = (workDir() / "cut.bag").string();
  const RunResult r = runLog2Bag(cut + " " + bag);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find(cut + ": truncated gzip stream"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the bag holds the"), std::string::npos) << r.err;
  const BagContent c = readBag(bag);
  EXPECT_GT(c.counts.at("/front_laser/scan"), 100u);
}

TEST(Log2Bag, RepairsStampsAndReportsEachKindOnce) {
  const std::string log =
      writeLog("stamps.log", {flaser(5.0), flaser(5.0), flaser(4.9), flaser(0.0), flaser(5.5)});
  const std::string bag = (workDir() / "stamps.bag").string();
  const RunResult r = runLog2Bag("--rate 20 --epoch 1000000000 " + log + " " + bag);
  ASSERT_EQ(r.status, 0) << r.err;
  const BagContent c = readBag(bag);
  ASSERT_EQ(c.scans.size(), 5u);
  for (std::size_t i = 1; i < c.scans.size(); ++i) {
    EXPECT_GT(c.scans[i].header.stamp, c.scans[i - 1].header.stamp);
  }
  EXPECT_EQ(c.scans[0].header.stamp, ros::Time(1000000005, 0));
  EXPECT_NEAR((c.scans[3].header.stamp - c.scans[2].header.stamp).toSec(), 0.05, 1e-6);
  EXPECT_NE(r.err.find("2 time stamps not after the previous one clamped"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("1 missing (zero) time stamps synthesised at 20 Hz"), std::string::npos)
      << r.err;
}

TEST(Log2Bag, PadHoldsTheLastPoseAndRepeatsTheStaticTransforms) {
  const std::string log = writeLog("pad.log", {flaser(5.0), flaser(5.1)});
  const std::string bag = (workDir() / "pad.bag").string();
  const RunResult r = runLog2Bag("--pad 30 " + log + " " + bag);
  ASSERT_EQ(r.status, 0) << r.err;
  const BagContent c = readBag(bag);
  ASSERT_EQ(c.scans.size(), 2u);
  ASSERT_EQ(c.tf_static.size(), 2u);
  EXPECT_EQ(c.tf_static[0].header.stamp, c.scans[0].header.stamp - ros::Duration(30.0));
  EXPECT_EQ(c.tf_static[1].header.stamp, c.scans[1].header.stamp + ros::Duration(30.0));
  ASSERT_EQ(c.tf.size(), 4u);  // one per scan, then the last pose held at +0.5 s and +30 s
  EXPECT_EQ(c.tf[2].header.stamp, c.scans[1].header.stamp + ros::Duration(0.5));
  EXPECT_EQ(c.tf[3].header.stamp, c.scans[1].header.stamp + ros::Duration(30.0));
  EXPECT_EQ(c.tf[3].transform.translation.x, c.tf[1].transform.translation.x);
  EXPECT_EQ(c.tf[3].transform.rotation.z, c.tf[1].transform.rotation.z);
}

TEST(Log2Bag, OdomOptionPublishesTheRawOdometry) {
  std::string line = "FLASER 180";
  for (int i = 0; i < 180; ++i) line += " 2.0";
  const std::string log = writeLog("odom.log", {line + " 1 2 0.5 1 2 0.5 7.0 host 7.0",
                                                line + " 1.5 2 0.5 4 -3 0.25 7.1 host 7.1"});
  const std::string bag = (workDir() / "odom.bag").string();
  const RunResult r = runLog2Bag("--odom " + log + " " + bag);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("(odom -> base_link)"), std::string::npos) << r.err;
  const BagContent c = readBag(bag);
  ASSERT_EQ(c.tf.size(), 2u);
  EXPECT_EQ(c.tf[1].header.frame_id, "odom");
  EXPECT_EQ(c.tf[1].child_frame_id, "base_link");
  const wavog::Pose2 p = toPose(c.tf[1].transform);
  EXPECT_DOUBLE_EQ(p.x, 4.0);
  EXPECT_DOUBLE_EQ(p.y, -3.0);
  EXPECT_NEAR(p.theta, 0.25, 1e-12);
}

TEST(Log2Bag, MissingInputAndBadUsage) {
  const std::string missing = (workDir() / "nope.log").string();
  RunResult r = runLog2Bag(missing + " " + (workDir() / "x.bag").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find(missing + ": cannot open"), std::string::npos) << r.err;
  r = runLog2Bag("only_one_argument");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("Usage: wavog_log2bag"), std::string::npos);
}

const auto* const kCleanup =
    ::testing::AddGlobalTestEnvironment(new wavog_tool_test::RemoveAtEnd(workDir()));

}  // namespace
