// Tests of wavog_offline, run as a program: the map from a converted fr079 bag equals the core map
// from the log read directly; the CARMEN log maps directly; outputs (PNG, PGM + YAML, native map,
// summary.json, snapshots) are written and consistent; with --ndt the NDT pictures have the
// expected size and summary.json's Gaussian counts equal the core's; the real
// laser_scan_matcher_demo.bag (no tf, frame "/laser") maps with --fixed-frame laser and its zero
// readings are rejected (REP 117); a laser mount given on the command line (--laser-parent,
// --laser-pose) maps a bag whose tf lacks it as the mount on /tf_static does; clear errors for a
// missing file, a missing topic, a bad mount and tf that never connects.
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2/buffer_core.h>
#include <tf2_msgs/TFMessage.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "../ros/driving_laser.h"
#include "program_runner.h"
#include "synthetic_log.h"
#include "wavog_mapping/core/motion_compensation.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/io/carmen_reader.h"
#include "wavog_mapping/io/image_io.h"
#include "wavog_mapping/io/ndt_image.h"
#include "wavog_mapping/ros/config.h"
#include "wavog_mapping/ros/scan_placement.h"

namespace {

namespace fs = std::filesystem;

constexpr std::size_t kScans = 300;

using wavog_tool_test::dataFile;
using wavog_tool_test::readText;
using wavog_tool_test::RunResult;

/// A summary.json, parsed (throws, so the test fails, when it is missing or not JSON).
nlohmann::json readJson(const fs::path& p) { return nlohmann::json::parse(readText(p)); }

fs::path workDir() {
  static const fs::path dir = wavog_tool_test::freshDir("wavog_offline_test");
  return dir;
}

RunResult run(const std::string& program, const std::string& args) {
  return wavog_tool_test::runProgram(program, args, workDir());
}

/// Compiled defaults, through the same loader as the tool.
wavog::MapParams defaultParams() {
  XmlRpc::XmlRpcValue empty;
  return wavog_ros::configFromXmlRpc(empty, nullptr).map;
}

struct MapDiff {
  std::size_t cells = 0;           ///< cells compared (union of both maps' bounds)
  std::size_t known_mismatch = 0;  ///< observed in one map only
  std::size_t value_mismatch = 0;  ///< observed in both, |difference| > 1e-4 * max(1, |value|)
  double max_diff = 0.0;
};

MapDiff compare(const wavog::WaveletMap& a, const wavog::WaveletMap& b) {
  MapDiff d;
  wavog::CellBox ba;
  wavog::CellBox bb;
  if (!a.bounds(0, &ba) || !b.bounds(0, &bb)) return d;
  const wavog::CellBox box{std::min(ba.min_x, bb.min_x), std::min(ba.min_y, bb.min_y),
                           std::max(ba.max_x, bb.max_x), std::max(ba.max_y, bb.max_y)};
  const wavog::Raster ra = a.exportScale(0, box, wavog::Aggregation::kMean);
  const wavog::Raster rb = b.exportScale(0, box, wavog::Aggregation::kMean);
  d.cells = ra.log_odds.size();
  for (std::size_t i = 0; i < d.cells; ++i) {
    if (ra.known[i] != rb.known[i]) {
      ++d.known_mismatch;
    } else if (ra.known[i]) {
      const double diff = std::fabs(static_cast<double>(ra.log_odds[i]) - rb.log_odds[i]);
      d.max_diff = std::max(d.max_diff, diff);
      if (diff > 1e-4 * std::max(1.0, std::fabs(static_cast<double>(ra.log_odds[i])))) {
        ++d.value_mismatch;
      }
    }
  }
  return d;
}

class OfflineFr079 : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    log_ = dataFile("fr079-corrected.log.gz");
    if (log_.empty()) return;
    bag_ = (workDir() / "fr079_300.bag").string();
    const RunResult c = run(WAVOG_LOG2BAG, "--quiet --max-scans 300 " + log_ + " " + bag_);
    ASSERT_EQ(c.status, 0) << c.err;
    out_ = (workDir() / "fr079_bag").string();
    bag_run_ =
        run(WAVOG_OFFLINE, "--no-progress --snapshot-every 5 --scale 0,2 -o " + out_ + " " + bag_);
  }

  static std::string log_;
  static std::string bag_;
  static std::string out_;
  static RunResult bag_run_;
};
std::string OfflineFr079::log_;
std::string OfflineFr079::bag_;
std::string OfflineFr079::out_;
RunResult OfflineFr079::bag_run_;

TEST_F(OfflineFr079, RealDataBagMapEqualsTheCoreMapFromTheLog) {
  ASSERT_FALSE(log_.empty()) << "shared data not found: set WAVOG_DATA_DIR";
  ASSERT_EQ(bag_run_.status, 0) << bag_run_.err;
  const wavog::MapParams params = defaultParams();
  wavog::WaveletMap from_bag(params);
  from_bag.load((fs::path(out_) / "map.wavog").string());

  // The core map from the log read directly (logged poses and angles).
  wavog::WaveletMap direct(params);
  const std::vector<wavog::CarmenScan> logged = wavog::readCarmenLog(log_, kScans);
  for (const wavog::CarmenScan& scan : logged) direct.integrate(scan.laser_pose, scan.view(0.0));

  // The same scans as the bag carries them: the LaserScan messages (float32 angles, +inf for no
  // return) placed by the node's placement in a tf2::BufferCore filled from the bag (headings
  // through quaternions).
  wavog::WaveletMap via_tf(params);
  double max_dxy = 0.0;
  double max_dtheta = 0.0;
  {
    rosbag::Bag bag(bag_, rosbag::bagmode::Read);
    tf2::BufferCore tf(ros::Duration(3600.0));
    for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
      if (const auto msg = m.instantiate<tf2_msgs::TFMessage>()) {
        for (const auto& t : msg->transforms)
          tf.setTransform(t, "test", m.getTopic() == "/tf_static");
      }
    }
    std::size_t i = 0;
    wavog::MotionCompensator compensator;
    for (const rosbag::MessageInstance& m :
         rosbag::View(bag, rosbag::TopicQuery("/front_laser/scan"))) {
      const auto scan = m.instantiate<sensor_msgs::LaserScan>();
      ASSERT_TRUE(scan);
      ASSERT_LT(i, logged.size());
      const wavog_ros::ScanPlacement placement =
          wavog_ros::placeScan(tf, *scan, wavog_ros::PlacementOptions{});
      ASSERT_TRUE(placement.placed()) << placement.error;
      wavog::Pose2 pose;
      const wavog::ScanView view = placement.placedView(*scan, &compensator, &pose);
      max_dxy = std::max(
          max_dxy, std::hypot(pose.x - logged[i].laser_pose.x, pose.y - logged[i].laser_pose.y));
      max_dtheta = std::max(
          max_dtheta, std::fabs(std::remainder(pose.theta - logged[i].laser_pose.theta, 2 * M_PI)));
      via_tf.integrate(pose, view);
      ++i;
    }
    ASSERT_EQ(i, kScans);
  }
  EXPECT_LT(max_dxy, 1e-12);
  EXPECT_LT(max_dtheta, 1e-12);
  const MapDiff exact = compare(via_tf, from_bag);
  EXPECT_EQ(exact.known_mismatch + exact.value_mismatch, 0u)
      << exact.known_mismatch << " known, " << exact.value_mismatch << " value mismatches";
  const MapDiff d = compare(direct, from_bag);
  EXPECT_GT(d.cells, 100000u);
  // Against the map of the logged values, the round-off of those two conversions (~1e-16 rad)
  // may flip a rare cell that lies on a classification boundary, nothing more.
  EXPECT_LE(d.known_mismatch + d.value_mismatch, d.cells / 100000)
      << "cells " << d.cells << " known mismatch " << d.known_mismatch << " value mismatch "
      << d.value_mismatch;
  RecordProperty("cells", static_cast<int>(d.cells));
  RecordProperty("mismatch", static_cast<int>(d.known_mismatch + d.value_mismatch));
  std::cout << "offline(bag) vs core(log): " << d.cells << " cells, " << d.known_mismatch
            << " known mismatches, " << d.value_mismatch << " value mismatches (max diff "
            << d.max_diff << "); vs core(log as the bag carries it): "
            << exact.known_mismatch + exact.value_mismatch << " mismatches\n";
}

TEST_F(OfflineFr079, RealDataWritesPicturesMapServerFilesSummaryAndSnapshots) {
  ASSERT_FALSE(log_.empty());
  ASSERT_EQ(bag_run_.status, 0) << bag_run_.err;
  const fs::path out(out_);
  for (const char* f : {"map_s0.png", "map_s0.pgm", "map_s0.yaml", "map_s2.png", "map_s2.pgm",
                        "map_s2.yaml", "map.wavog", "summary.json"}) {
    EXPECT_TRUE(fs::exists(out / f)) << f;
  }
  EXPECT_FALSE(fs::exists(out / "map_s3.png"));  // --scale 0,2 overrides publish_scales
  const wavog::Image png = wavog::readPng((out / "map_s0.png").string());
  const wavog::Image pgm = wavog::readPgm((out / "map_s0.pgm").string());
  EXPECT_EQ(png.channels, 3);
  EXPECT_EQ(png.width, pgm.width);
  EXPECT_EQ(png.height, pgm.height);
  EXPECT_GT(png.width, 100);
  const wavog::Image pgm2 = wavog::readPgm((out / "map_s2.pgm").string());
  EXPECT_NEAR(pgm2.width, pgm.width / 4.0, 3.0);
  const std::string yaml = readText(out / "map_s0.yaml");
  EXPECT_NE(yaml.find("image: map_s0.pgm\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("resolution: 0.05"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("negate: 0\n"), std::string::npos) << yaml;
  const nlohmann::json json = readJson(out / "summary.json");
  EXPECT_EQ(json["scans_integrated"], 300) << json;
  EXPECT_EQ(json["scans_dropped"], 0) << json;
  EXPECT_EQ(json["input_type"], "bag") << json;
  EXPECT_EQ(json["topics"], nlohmann::json::array({"/front_laser/scan"})) << json;
  EXPECT_EQ(json["policy"], "forget") << json;
  for (const char* key : {"wall_time_s", "scans_per_s"}) EXPECT_TRUE(json[key].is_number()) << key;
  for (const char* key : {"bytes_per_observed_cell", "nodes"}) {
    EXPECT_TRUE(json["map"][key].is_number()) << key << "\n" << json;
  }
  ASSERT_FALSE(json["snapshots"].empty()) << json;
  EXPECT_EQ(json["snapshots"][0].get<std::string>().rfind("snapshots/", 0), 0u) << json;
  // 300 scans of fr079 span about 64 s of log time: snapshots at 0, 5, 10, ... s.
  std::size_t snapshots = 0;
  for (const auto& e : fs::directory_iterator(out / "snapshots"))
    snapshots += e.path().extension() == ".png";
  EXPECT_GE(snapshots, 10u);
  EXPECT_TRUE(fs::exists(out / "snapshots" / "t00000.0_s0.png"));
}

TEST_F(OfflineFr079, RealDataCarmenLogDirectlyWithPolicyAndScaleOptions) {
  ASSERT_FALSE(log_.empty());
  const std::string out = (workDir() / "fr079_log").string();
  const RunResult r = run(WAVOG_OFFLINE,
                          "--no-progress --max-scans 300 --policy clamp --scale 1 "
                          "--aggregation max -o " +
                              out + " " + log_);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json json = readJson(fs::path(out) / "summary.json");
  EXPECT_EQ(json["input_type"], "carmen") << json;
  EXPECT_EQ(json["policy"], "clamp") << json;
  EXPECT_EQ(json["aggregation"], "max") << json;
  EXPECT_EQ(json["scans_integrated"], 300) << json;
  EXPECT_TRUE(fs::exists(fs::path(out) / "map_s1.png"));
  EXPECT_FALSE(fs::exists(fs::path(out) / "map_s0.png"));
  // The native map is the clamp policy's map of the same scans.
  wavog::MapParams params = wavog::MapParams::defaultsFor(wavog::PolicyType::kClamp);
  wavog::WaveletMap loaded(params);
  loaded.load((fs::path(out) / "map.wavog").string());
  wavog::WaveletMap direct(params);
  for (const wavog::CarmenScan& scan : wavog::readCarmenLog(log_, kScans)) {
    direct.integrate(scan.laser_pose, scan.view(0.0));
  }
  const MapDiff d = compare(direct, loaded);
  EXPECT_EQ(d.known_mismatch + d.value_mismatch, 0u) << d.known_mismatch << " " << d.value_mismatch;
}

TEST(OfflineNdt, RealDataPicturesAndCountsOfTheGaussiansPerScaleEqualTheCoreMaps) {
  const std::string log = dataFile("fr079-corrected.log.gz");
  ASSERT_FALSE(log.empty()) << "shared data not found: set WAVOG_DATA_DIR";
  constexpr std::size_t kNdtScans = 150;
  const fs::path out = workDir() / "fr079_ndt";
  const RunResult r =
      run(WAVOG_OFFLINE, "--no-progress --ndt --max-scans " + std::to_string(kNdtScans) +
                             " --scale 0,2 -o " + out.string() + " " + log);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json json = readJson(out / "summary.json");
  EXPECT_EQ(json["ndt"], true) << json;
  EXPECT_FALSE(fs::exists(out / "ndt_s1.png"));

  // The same scans through the core directly (the CARMEN path is exact, see above).
  wavog::MapParams params = defaultParams();
  params.ndt = true;
  wavog::WaveletMap direct(params);
  for (const wavog::CarmenScan& scan : wavog::readCarmenLog(log, kNdtScans)) {
    direct.integrate(scan.laser_pose, scan.view(0.0));
  }
  EXPECT_EQ(json["map"]["ndt_cells"], direct.stats().ndt_cells) << json;
  ASSERT_EQ(json["scales"].size(), 2u) << json;
  const wavog::NdtRenderOptions options;
  for (const nlohmann::json& entry : json["scales"]) {
    const int scale = entry["scale"];
    SCOPED_TRACE("scale " + std::to_string(scale));
    // Over the whole map: no Gaussian lies outside the picture's cropped box.
    wavog::CellBox box;
    ASSERT_TRUE(direct.bounds(scale, &box));
    const wavog::NdtLayer layer = direct.exportNdt(scale, box);
    ASSERT_GT(layer.cells.size(), 100u);
    const nlohmann::json& ndt = entry["ndt"];
    EXPECT_EQ(ndt["gaussians"], layer.cells.size()) << ndt;
    double weight = 0.0;
    for (const wavog::NdtCell& c : layer.cells) weight += c.weight;
    const double mean_weight = weight / static_cast<double>(layer.cells.size());
    EXPECT_NEAR(ndt["mean_weight"].get<double>(), mean_weight, 1e-9 * mean_weight) << ndt;
    EXPECT_GT(mean_weight, 0.0);

    // The picture: the occupancy map's cells times the upscale, the largest within the budget.
    const wavog::Image png = wavog::readPng((out / ndt["png"].get<std::string>()).string());
    const int k = ndt["upscale"];
    const std::int64_t w = entry["width"];
    const std::int64_t h = entry["height"];
    ASSERT_GE(k, 1);
    ASSERT_LE(k, options.max_upscale);
    EXPECT_TRUE(k == options.max_upscale ||
                static_cast<double>(w * h) * (k + 1) * (k + 1) > options.max_pixels);
    EXPECT_EQ(png.channels, 3);
    EXPECT_EQ(png.width, w * k);
    EXPECT_EQ(png.height, h * k);
    // Every mean has its own pixel (distinct cells) in the mean colour, no map pixel has it, and
    // the occupied walls have outlines.
    std::size_t means = 0;
    std::size_t outlines = 0;
    for (int y = 0; y < png.height; ++y) {
      for (int x = 0; x < png.width; ++x) {
        const std::uint8_t* p = png.at(x, y);
        means += p[0] == options.mean_colour.r && p[1] == options.mean_colour.g &&
                 p[2] == options.mean_colour.b;
        outlines += p[0] == options.occupied_colour.r && p[1] == options.occupied_colour.g &&
                    p[2] == options.occupied_colour.b;
      }
    }
    EXPECT_GE(means, layer.cells.size());
    EXPECT_GT(outlines, layer.cells.size() / 2);
  }
}

TEST(Offline, RealDataLaserScanMatcherDemoBagWithFixedFrameRejectsZeroReadings) {
  const std::string bag = dataFile("laser_scan_matcher_demo.bag");
  ASSERT_FALSE(bag.empty()) << "shared data not found: set WAVOG_DATA_DIR";
  // Without tf the default fixed frame "map" never connects: a clear error listing the frames.
  const std::string out = (workDir() / "lsm").string();
  RunResult r = run(WAVOG_OFFLINE, "--no-progress -o " + out + " " + bag);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("tf never connects the scan frame 'laser' to the fixed frame 'map'"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("the bag has no /tf or /tf_static"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--fixed-frame"), std::string::npos) << r.err;

  r = run(WAVOG_OFFLINE, "--no-progress --fixed-frame laser -o " + out + " " + bag);
  ASSERT_EQ(r.status, 0) << r.err;
  // The '/laser' frame id is stripped, and said so once (as the node does), not once per scan.
  const std::size_t said = r.err.find("frame_id '/laser' has a leading '/'");
  ASSERT_NE(said, std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("frame_id '/laser'", said + 1), std::string::npos) << r.err;
  // Count the bag's invalid readings: zeros (Hokuyo error codes) and those below range_min.
  std::uint64_t invalid = 0;
  std::uint64_t zeros = 0;
  std::uint64_t total = 0;
  {
    rosbag::Bag b(bag, rosbag::bagmode::Read);
    for (const rosbag::MessageInstance& m : rosbag::View(b)) {
      const auto scan = m.instantiate<sensor_msgs::LaserScan>();
      if (!scan) continue;
      EXPECT_EQ(scan->header.frame_id, "/laser");
      for (float x : scan->ranges) {
        ++total;
        zeros += x == 0.0f ? 1 : 0;
        invalid += (std::isnan(x) || x <= 0.0f || x < scan->range_min) ? 1 : 0;
      }
    }
  }
  EXPECT_GT(zeros, total / 50);  // about 5 %
  const nlohmann::json json = readJson(fs::path(out) / "summary.json");
  EXPECT_EQ(json["scans_integrated"], 360) << json;
  EXPECT_EQ(json["beams"]["invalid"], invalid)
      << "expected " << invalid << " invalid beams (" << zeros << " zeros)\n"
      << json;
  EXPECT_EQ(json["fixed_frame"], "laser") << json;
  // No cell at the laser's own position is occupied: zero readings never became hits.
  wavog::WaveletMap map(defaultParams());
  map.load((fs::path(out) / "map.wavog").string());
  EXPECT_LE(map.value(map.cellAt(0.0, 0.0)), 0.0f);
}

// The drive of driving_laser.h written to a bag, the laser in `laser_frame`, with its static mount
// on /tf_static or without it.
std::string writeDrivingBag(const std::string& name, const std::string& laser_frame,
                            bool with_mount) {
  namespace dl = driving_laser;
  const std::string bag_path = (workDir() / name).string();
  rosbag::Bag bag(bag_path, rosbag::bagmode::Write);
  if (with_mount) {
    tf2_msgs::TFMessage statics;
    statics.transforms.push_back(dl::mount(laser_frame));
    bag.write("/tf_static", dl::kT0, statics);
  }
  for (const auto& t : dl::drive()) {
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(t);
    bag.write("/tf", t.header.stamp, tf);
  }
  for (int i = 0; i < dl::kScans; ++i) {
    const sensor_msgs::LaserScan s = dl::scanAt(dl::scanTime(i), laser_frame);
    bag.write("/scan", s.header.stamp, s);
  }
  return bag_path;
}

TEST(Offline, UpsideDownLaserAndMotionCompensationInABag) {
  // A robot driving along x at 1 m/s with a laser mounted upside down 0.2 m ahead of base_link;
  // beams are timed (time_increment), so each sweep is re-binned. The placement itself (poses,
  // mirroring) is tested in test/ros/test_scan_placement.cpp; here: the bag's tf (with its leading
  // '/' frames) reaches it and the summary counts it.
  namespace dl = driving_laser;
  const std::string bag_path = writeDrivingBag("synthetic.bag", "/laser_down", true);
  const std::string out = (workDir() / "synthetic").string();
  const RunResult r = run(WAVOG_OFFLINE, "--no-progress -o " + out + " " + bag_path);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json json = readJson(fs::path(out) / "summary.json");
  EXPECT_EQ(json["scans_integrated"], 20) << json;
  EXPECT_EQ(json["motion_compensated"], 20) << json;
  EXPECT_EQ(json["beams"]["invalid"], 20) << json;

  wavog::WaveletMap offline(defaultParams());
  offline.load((fs::path(out) / "map.wavog").string());
  // The last scan's short beam hit the map at -45 deg from the laser (mirrored), not at +45 deg.
  const double x = dl::kMount + dl::kSpeed * (dl::scanTime(dl::kScans - 1) + dl::kSweep / 2);
  const double c = std::cos(M_PI / 4);
  // With forgetting (gamma 0.3), one hit on a cell seen free before lifts it from about -2 to
  // 0.7 * -2 + 0.3 * 3.5 = -0.35; its mirror image stays free.
  const float hit = offline.value(offline.cellAt(x + c, -c));
  const float mirror = offline.value(offline.cellAt(x + c, c));
  EXPECT_GT(hit, -0.5f);
  EXPECT_LT(mirror, -1.5f);
}

TEST(Offline, LaserMountFromTheCommandLineWhenTheBagsTfLacksIt) {
  // A bag whose tf has the robot but not its laser (as the oko bag): the tool says how to give the
  // mount; given as the launch's laser_parent / laser_pose would give it, the map is the map of
  // the same bag with the mount on /tf_static.
  const std::string mounted = writeDrivingBag("mounted.bag", "laser_down", true);
  const std::string bare = writeDrivingBag("no_mount.bag", "laser_down", false);
  const std::string out_mounted = (workDir() / "mounted").string();
  const std::string out_bare = (workDir() / "no_mount").string();
  RunResult r = run(WAVOG_OFFLINE, "--no-progress -o " + out_bare + " " + bare);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("tf never connects the scan frame 'laser_down'"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("--laser-parent"), std::string::npos) << r.err;

  r = run(WAVOG_OFFLINE, "--no-progress -o " + out_mounted + " " + mounted);
  ASSERT_EQ(r.status, 0) << r.err;
  // Upside down 0.2 m ahead of base_link: roll pi (x y z yaw pitch roll).
  const std::string pose =
      " --laser-pose \"" + std::to_string(driving_laser::kMount) + " 0 0 0 0 3.141592653589793\" ";
  r = run(WAVOG_OFFLINE,
          "--no-progress --laser-parent /base_link" + pose + "-o " + out_bare + " " + bare);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json json = readJson(fs::path(out_bare) / "summary.json");
  EXPECT_EQ(json["scans_integrated"], 20) << json;
  EXPECT_EQ(
      json["laser_mount"].get<std::string>().rfind("base_link <- laser_down: 0.2 0 0 0 0 3.14", 0),
      0u)
      << json;
  wavog::WaveletMap a(defaultParams()), b(defaultParams());
  a.load((fs::path(out_mounted) / "map.wavog").string());
  b.load((fs::path(out_bare) / "map.wavog").string());
  const MapDiff d = compare(a, b);
  EXPECT_GT(d.cells, 1000u);
  EXPECT_EQ(d.known_mismatch, 0u);
  EXPECT_EQ(d.value_mismatch, 0u) << "max difference " << d.max_diff;

  // A bag that has the mount: two places for one frame is an error, not a silent choice.
  r = run(WAVOG_OFFLINE,
          "--no-progress --laser-parent base_link" + pose + "-o " + out_mounted + " " + mounted);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("the bag's tf already places the scan frame 'laser_down' in 'base_link'"),
            std::string::npos)
      << r.err;
  r = run(WAVOG_OFFLINE, "--no-progress --laser-parent laser_down -o " + out_bare + " " + bare);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("is the scan frame itself"), std::string::npos) << r.err;
}

TEST(Offline, AbsurdPoseFromTfIsRefusedAsTheNodeRefusesIt) {
  // The drive of the test above, but one odometry sample (at 0.51 s) jumps 2 km ahead and back, as
  // the oko bag's odometry does: scan 5 (0.505-0.523 s) starts between it and a sane sample, so tf
  // places it 1 km away. The node refuses such a scan (pose_check.h); so does wavog_offline, and
  // its map stays where the robot drove.
  namespace dl = driving_laser;
  const std::string bag_path = (workDir() / "jump.bag").string();
  {
    rosbag::Bag bag(bag_path, rosbag::bagmode::Write);
    tf2_msgs::TFMessage statics;
    statics.transforms.push_back(dl::mount("laser_down"));
    bag.write("/tf_static", dl::kT0, statics);
    for (auto t : dl::drive()) {
      if (t.header.stamp == dl::kT0 + ros::Duration(0.51)) t.transform.translation.x = 2000.0;
      tf2_msgs::TFMessage tf;
      tf.transforms.push_back(t);
      bag.write("/tf", t.header.stamp, tf);
    }
    for (int i = 0; i < dl::kScans; ++i) {
      const sensor_msgs::LaserScan s = dl::scanAt(dl::scanTime(i), "laser_down");
      bag.write("/scan", s.header.stamp, s);
    }
  }
  const std::string out = (workDir() / "jump").string();
  const RunResult r = run(WAVOG_OFFLINE, "--no-progress -o " + out + " " + bag_path);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json json = readJson(fs::path(out) / "summary.json");
  EXPECT_EQ(json["scans_integrated"], 19) << json;
  EXPECT_EQ(json["dropped_by_reason"]["absurd_pose"], 1) << json;
  EXPECT_NE(r.err.find("absurd pose"), std::string::npos) << r.err;
  wavog::WaveletMap offline(defaultParams());
  offline.load((fs::path(out) / "map.wavog").string());
  wavog::CellBox box;
  ASSERT_TRUE(offline.bounds(0, &box));
  EXPECT_LT(static_cast<double>(box.max_x) * offline.resolution(), 100.0);  // not 1 km away
}

TEST(Offline, TruncatedGzipLogIsReportedAfterMappingWhatWasRead) {
  const std::string whole = wavog_test::gzipDeflate(wavog_test::syntheticFlaserLog(400));
  const std::string bytes = whole.substr(0, whole.size() / 2);  // about 200 scans
  const std::string cut = (workDir() / "cut.log.gz").string();
  std::ofstream(cut, std::ios::binary) << bytes;
  const std::string out = (workDir() / "cut").string();
  const RunResult r = run(WAVOG_OFFLINE, "--no-progress -o " + out + " " + cut);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("error: " + cut + ": truncated gzip stream"), std::string::npos) << r.err;
  const nlohmann::json json = readJson(fs::path(out) / "summary.json");
  EXPECT_EQ(json["read_error"].get<std::string>().rfind(cut + ": truncated gzip stream", 0), 0u)
      << json;
  EXPECT_TRUE(fs::exists(fs::path(out) / "map_s0.png"));
}

TEST(Offline, ClearErrors) {
  const std::string out = (workDir() / "errors").string();
  const std::string missing = (workDir() / "missing.bag").string();
  RunResult r = run(WAVOG_OFFLINE, "--no-progress -o " + out + " " + missing);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find(missing + ": cannot open"), std::string::npos) << r.err;

  // A bag of 50 scans on /front_laser/scan, from a log made here.
  const std::string log = (workDir() / "errors.log").string();
  std::ofstream(log) << wavog_test::syntheticFlaserLog(50);
  const std::string bag = (workDir() / "errors.bag").string();
  const RunResult c = run(WAVOG_LOG2BAG, "--quiet " + log + " " + bag);
  ASSERT_EQ(c.status, 0) << c.err;
  r = run(WAVOG_OFFLINE, "--no-progress --topics rear_laser/scan -o " + out + " " + bag);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("the bag has no topic 'rear_laser/scan'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/front_laser/scan (sensor_msgs/LaserScan, 50 msgs)"), std::string::npos)
      << r.err;

  r = run(WAVOG_OFFLINE, "--no-progress --policy sometimes -o " + out + " " + bag);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("policy"), std::string::npos) << r.err;

  // Numbers are read whole: trailing characters are an error naming the option.
  r = run(WAVOG_OFFLINE, "--no-progress --resolution 0.05x -o " + out + " " + bag);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--resolution: not a number: '0.05x'"), std::string::npos) << r.err;
  // A negative resolution is refused by name (issue 41: it mapped at the YAML's, exit 0); 0 keeps
  // the YAML's.
  r = run(WAVOG_OFFLINE, "--no-progress --resolution -1 -o " + out + " " + bag);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--resolution (-1) must be > 0 m"), std::string::npos) << r.err;
  r = run(WAVOG_OFFLINE, "--no-progress --resolution 500 -o " + out + " " + bag);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("resolution (500) must be"), std::string::npos) << r.err;
  r = run(WAVOG_OFFLINE,
          "--no-progress --laser-parent base_link --laser-pose \"0 0 1\" -o " + out + " " + bag);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--laser-pose: 6 numbers"), std::string::npos) << r.err;
  r = run(WAVOG_OFFLINE, "--no-progress --laser-parent base_link --laser-pose \"0 0 0 0 0 x\" -o " +
                             out + " " + bag);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--laser-pose: not a number: 'x'"), std::string::npos) << r.err;
  r = run(WAVOG_OFFLINE, "--no-progress --laser-pose \"0 0 0 0 0 0\" -o " + out + " " + bag);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--laser-pose needs --laser-parent"), std::string::npos) << r.err;
  r = run(WAVOG_OFFLINE, "--no-progress --scale 0,2.5 -o " + out + " " + bag);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--scale: not a whole number >= 0: '2.5'"), std::string::npos) << r.err;

  const std::string yaml = (workDir() / "bad.yaml").string();
  std::ofstream(yaml) << "resolution: [1, 2\n";
  r = run(WAVOG_OFFLINE, "--no-progress -c " + yaml + " -o " + out + " " + bag);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find(yaml), std::string::npos) << r.err;

  r = run(WAVOG_OFFLINE, "");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("Usage: wavog_offline"), std::string::npos) << r.err;
}

const auto* const kCleanup =
    ::testing::AddGlobalTestEnvironment(new wavog_tool_test::RemoveAtEnd(workDir()));

}  // namespace
