// A fleet over ROS (issue 30; test/fleet.test): three simulated car-park vehicles, each mapper in
// its own process and namespace streaming the scans it integrated, one wavog_fleet node. v1 runs
// from the start (launch), v2 is started by this test and killed (SIGKILL) at 15 s, v3 starts 20 s
// late. Checks: the streams are the default 16-bit codes (PlacedScan version 2); the fleet map
// equals, cell for cell, one map fed every streamed scan in stamp order, and v1's and v3's own
// maps their streams replayed alone (the mappers integrated the decoded codes); it gets at least as many ground-truth cells right as the best single vehicle; v2 is
// stale in ~fleet_status and /diagnostics and its cells stay; v3 is caught up. Each process has
// its own loopback address (fleet.test), as on distinct hosts: checked at the master. A fleet
// node started after the run from the first one's save_map (map_file) holds that map exactly.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <ros/master.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <signal.h>
#include <std_srvs/Trigger.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "fleet/placed_scan.h"
#include "fleet_test_support.h"
#include "map_compare.h"
#include "wavog_mapping/FleetStatus.h"
#include "wavog_mapping/PlacedScan.h"
#include "wavog_mapping/SaveMap.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/ros/config.h"
#include "wavog_mapping/sim/ground_truth.h"
#include "wavog_mapping/sim/world.h"

namespace {

constexpr double kEpoch = 1.7e9;  // wavog_simulate's time 0
constexpr double kKillAt = 15.0;  // v2 is killed (sim s)
constexpr double kLateStart = 20.0;  // v3 starts (sim s)
const std::vector<std::string> kVehicles = {"v1", "v2", "v3"};

/// The loopback address each process of the test has (test/fleet.test), as hosts would.
const std::map<std::string, std::string> kHosts = {{"/wavog_fleet", "127.0.0.2"},
                                                   {"/v1/wavog_mapping", "127.0.0.3"},
                                                   {"/v2/wavog_mapping", "127.0.0.4"},
                                                   {"/v3/wavog_mapping", "127.0.0.5"}};
constexpr const char* kTestHost = "127.0.0.6";

using fleet_test::exited;
using fleet_test::spawn;
using fleet_test::stop;

/// Stops a child at the end of the test, also when an assertion returns early (a child left
/// running would hold the test's output pipe open).
struct Child {
  pid_t pid = -1;
  ~Child() { stop(pid); }
};

pid_t startMapper(const std::string& ns) {
  return spawn({WAVOG_NODE_BIN, "__ns:=/" + ns, "__name:=wavog_mapping"},
               kHosts.at("/" + ns + "/wavog_mapping"));
}

/// The host of `node`'s XML-RPC URI as the master has it (where its peers connect); empty when
/// the master does not know the node.
std::string nodeHost(const std::string& node) {
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  args[1] = node;
  if (!ros::master::execute("lookupNode", args, result, payload, false)) return "";
  if (result.getType() != XmlRpc::XmlRpcValue::TypeArray || result.size() < 3 ||
      static_cast<int>(result[0]) != 1) {
    return "";
  }
  std::string uri = result[2];  // http://host:port/
  const auto begin = uri.find("://");
  if (begin == std::string::npos) return "";
  uri = uri.substr(begin + 3);
  return uri.substr(0, uri.find(':'));
}

struct Recorder {
  std::mutex mutex;
  std::vector<std::vector<wavog_mapping::PlacedScan::ConstPtr>> scans{kVehicles.size()};
  wavog_mapping::FleetStatus::ConstPtr status;
  std::map<std::string, diagnostic_msgs::DiagnosticStatus> diagnostics;
  std::vector<double> lag_max = std::vector<double>(kVehicles.size(), 0.0);  ///< over the run
  std::vector<double> publish_lag_max = std::vector<double>(kVehicles.size(), 0.0);
};

bool saveMap(const std::string& service, const std::string& path) {
  wavog_mapping::SaveMap srv;
  srv.request.path = path;
  if (!ros::service::waitForService(service, ros::Duration(10.0))) return false;
  return ros::service::call(service, srv) && srv.response.success;
}

/// Calls a node's ~flush (std_srvs/Trigger): true once it answered with success.
bool flush(const std::string& service) {
  std_srvs::Trigger srv;
  if (!ros::service::waitForService(service, ros::Duration(10.0))) return false;
  return ros::service::call(service, srv) && srv.response.success;
}

wavog::WaveletMap loadMap(const wavog::MapParams& params, const std::string& path) {
  wavog::WaveletMap m(params);
  m.load(path);
  return m;
}

/// Ground-truth cells (filled occupancy at time t) the map observed and classifies right.
std::size_t truthCellsRight(const wavog::WaveletMap& map, const wavog::sim::World& world, double t) {
  const auto window = wavog::sim::GridWindow::covering(world.region_min, world.region_max, 0.1);
  const std::vector<std::uint8_t> truth = wavog::sim::occupancyAt(world, t, window);
  std::size_t right = 0;
  for (int row = 0; row < window.height; ++row) {
    for (int col = 0; col < window.width; ++col) {
      const auto c = window.centre(col, row);
      const wavog::CellIndex cell = map.cellAt(c.x(), c.y());
      if (!map.isObserved(cell)) continue;
      right += (map.value(cell) > 0.0f) == (truth[window.index(col, row)] != 0);
    }
  }
  return right;
}

TEST(Fleet, ThreeVehiclesOneMap) {
  ros::NodeHandle nh;
  Recorder rec;
  std::vector<ros::Subscriber> subs;
  for (std::size_t k = 0; k < kVehicles.size(); ++k) {
    subs.push_back(nh.subscribe<wavog_mapping::PlacedScan>(
        "/" + kVehicles[k] + "/fleet_scans", 100000,
        [&rec, k](const wavog_mapping::PlacedScan::ConstPtr& m) {
          std::lock_guard<std::mutex> lock(rec.mutex);
          rec.scans[k].push_back(m);
        }));
  }
  subs.push_back(nh.subscribe<wavog_mapping::FleetStatus>(
      "/wavog_fleet/fleet_status", 10, [&rec](const wavog_mapping::FleetStatus::ConstPtr& s) {
        std::lock_guard<std::mutex> lock(rec.mutex);
        rec.status = s;
        for (std::size_t k = 0; k < s->vehicles.size() && k < kVehicles.size(); ++k) {
          rec.lag_max[k] = std::max(rec.lag_max[k], s->vehicles[k].lag_max);
          rec.publish_lag_max[k] = std::max(rec.publish_lag_max[k], s->vehicles[k].publish_lag_max);
        }
      }));
  subs.push_back(nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 100, [&rec](const diagnostic_msgs::DiagnosticArray::ConstPtr& a) {
        std::lock_guard<std::mutex> lock(rec.mutex);
        for (const auto& s : a->status) rec.diagnostics[s.name] = s;
      }));
  ros::AsyncSpinner spinner(2);
  spinner.start();

  ASSERT_TRUE(ros::service::waitForService("/wavog_fleet/save_map", ros::Duration(30.0)));
  ASSERT_TRUE(ros::service::waitForService("/v1/wavog_mapping/save_map", ros::Duration(30.0)));
  Child v2_child, v3_child, player_child;
  pid_t& v2 = v2_child.pid;
  pid_t& v3 = v3_child.pid;
  v2 = startMapper("v2");
  ASSERT_TRUE(ros::service::waitForService("/v2/wavog_mapping/save_map", ros::Duration(30.0)));
  // Each process is reached at its own address (fleet.test), as on another machine.
  EXPECT_EQ(ros::network::getHost(), kTestHost);
  for (const char* node : {"/wavog_fleet", "/v1/wavog_mapping", "/v2/wavog_mapping"}) {
    EXPECT_EQ(nodeHost(node), kHosts.at(node)) << node;
  }
  ros::WallDuration(1.0).sleep();  // subscriptions connect
  player_child.pid = spawn({"rosbag", "play", "--clock", "-q", WAVOG_FLEET_BAG});
  const pid_t player = player_child.pid;
  const std::string stem = "/tmp/wavog_fleet_test_" + std::to_string(getpid());
  bool checked_stale = false, checked_late = false;
  wavog_mapping::VehicleStatus v2_at_kill_check, v1_at_kill_check, v3_at_check;
  std::string v2_diag_message;
  int v2_diag_level = -1;
  while (!exited(player)) {
    const double t = ros::Time::now().toSec() - kEpoch;
    if (v2 > 0 && t >= kKillAt) {
      ASSERT_TRUE(saveMap("/v2/wavog_mapping/save_map", stem + "_v2.wmap"));
      kill(v2, SIGKILL);
      waitpid(v2, nullptr, 0);
      v2 = -1;
    }
    if (v3 < 0 && t >= kLateStart) v3 = startMapper("v3");
    if (!checked_stale && t >= kKillAt + 4.0) {
      std::lock_guard<std::mutex> lock(rec.mutex);
      if (rec.status && (rec.status->header.stamp.toSec() - kEpoch) >= kKillAt + 3.5) {
        checked_stale = true;
        v1_at_kill_check = rec.status->vehicles[0];
        v2_at_kill_check = rec.status->vehicles[1];
        for (const auto& d : rec.diagnostics) {
          if (d.first.find("v2 vehicle") != std::string::npos) {
            v2_diag_level = d.second.level;
            v2_diag_message = d.second.message;
          }
        }
      }
    }
    if (!checked_late && t >= kLateStart + 5.0) {
      std::lock_guard<std::mutex> lock(rec.mutex);
      if (rec.status && (rec.status->header.stamp.toSec() - kEpoch) >= kLateStart + 4.5) {
        checked_late = true;
        v3_at_check = rec.status->vehicles[2];
      }
    }
    ros::WallDuration(0.05).sleep();
  }
  player_child.pid = -1;  // exited and reaped
  // The end of the input, by state rather than by time (a loaded machine takes longer): the live
  // mappers flush what waits for tf and stream it, and the fleet node has received every scan
  // the test recorded and holds none in its reorder buffer (fleet_reorder_wait, then the
  // horizon: v1 and v3 silent for fleet_stale_timeout), with no new scan for 4 polls a second
  // apart (longer than the mappers' idle_timeout, after which they flush by themselves).
  ASSERT_TRUE(flush("/v1/wavog_mapping/flush"));
  if (v3 > 0) ASSERT_TRUE(flush("/v3/wavog_mapping/flush"));
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(120.0);
  std::vector<std::size_t> counts;
  std::string last_state = "no fleet status";  // the last poll's, for a failure's message
  for (int settled = 0; settled < 4;) {
    ASSERT_LT(ros::WallTime::now(), give_up) << "the fleet node never received and integrated "
                                                "every streamed scan; last poll: "
                                             << last_state;
    ros::WallDuration(1.0).sleep();
    ASSERT_TRUE(flush("/wavog_fleet/flush"));  // publishes ~fleet_status
    ros::WallDuration(0.2).sleep();
    std::lock_guard<std::mutex> lock(rec.mutex);
    bool done =
        rec.status && rec.status->buffered == 0 && rec.status->vehicles.size() == kVehicles.size();
    std::vector<std::size_t> now_counts;
    std::ostringstream state;
    if (rec.status) state << "buffered " << rec.status->buffered;
    for (std::size_t k = 0; k < kVehicles.size(); ++k) {
      now_counts.push_back(rec.scans[k].size());
      const bool known = rec.status && k < rec.status->vehicles.size();
      done = done && known && rec.status->vehicles[k].received == rec.scans[k].size();
      state << "; " << kVehicles[k] << " recorded " << rec.scans[k].size() << ", fleet received "
            << (known ? std::to_string(rec.status->vehicles[k].received) : std::string("-"));
    }
    last_state = state.str();
    settled = done && now_counts == counts ? settled + 1 : 0;
    counts = now_counts;
  }
  ASSERT_TRUE(saveMap("/wavog_fleet/save_map", stem + "_fleet.wmap"));
  ASSERT_TRUE(saveMap("/v1/wavog_mapping/save_map", stem + "_v1.wmap"));
  ASSERT_GT(v3, 0);
  EXPECT_EQ(nodeHost("/v3/wavog_mapping"), kHosts.at("/v3/wavog_mapping"));
  ASSERT_TRUE(saveMap("/v3/wavog_mapping/save_map", stem + "_v3.wmap"));

  // ---- v2 killed: stale, in ~fleet_status and /diagnostics; v1 streaming meanwhile.
  ASSERT_TRUE(checked_stale);
  EXPECT_TRUE(v2_at_kill_check.stale);
  EXPECT_FALSE(v1_at_kill_check.stale);
  EXPECT_EQ(v2_diag_level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_NE(v2_diag_message.find("stale"), std::string::npos) << v2_diag_message;
  // ---- v3, 20 s late: streaming and integrated within seconds.
  ASSERT_TRUE(checked_late);
  EXPECT_FALSE(v3_at_check.stale);
  EXPECT_GT(v3_at_check.integrated, 100u);

  // ---- every scan the fleet received was integrated, in order (nothing late, nothing refused).
  wavog_mapping::FleetStatus::ConstPtr status;
  std::vector<std::vector<wavog_mapping::PlacedScan::ConstPtr>> scans;
  std::vector<double> lag_max, publish_lag_max;
  {
    std::lock_guard<std::mutex> lock(rec.mutex);
    status = rec.status;
    scans = rec.scans;
    lag_max = rec.lag_max;
    publish_lag_max = rec.publish_lag_max;
  }
  ASSERT_TRUE(status);
  std::size_t total = 0;
  for (std::size_t k = 0; k < kVehicles.size(); ++k) {
    const auto& v = status->vehicles[k];
    SCOPED_TRACE(kVehicles[k]);
    EXPECT_GT(scans[k].size(), 400u);
    EXPECT_EQ(v.received, scans[k].size());
    EXPECT_EQ(v.integrated, scans[k].size());
    EXPECT_EQ(v.integrated_late + v.dropped_late + v.lost + v.index_regressions + v.index_jumps +
                  v.dropped_version + v.dropped_frame + v.dropped_bad_stamp + v.dropped_bad_pose +
                  v.dropped_bad_size + v.dropped_refused + v.dropped_overflow,
              0u);
    // The default stream (fleet_stream_format: uint16): 361 ranges of 2 bytes each, and more.
    for (const auto& m : scans[k]) {
      ASSERT_EQ(m->version, wavog_mapping::PlacedScan::VERSION_UINT16);
      ASSERT_EQ(m->range_codes.size(), 361u);
    }
    EXPECT_GT(v.bytes, scans[k].size() * 722u);
    EXPECT_LT(v.bytes, scans[k].size() * 1444u);
    for (std::size_t i = 0; i < scans[k].size(); ++i) ASSERT_EQ(scans[k][i]->index, i);
    total += scans[k].size();
    // A scan reaches the published layers after its integration: the largest lag to the layers'
    // publication is at least the largest lag to integration (every scan was published: save_map
    // publishes), and both include the reorder wait (3 wall s, fleet_map.yaml).
    EXPECT_GE(lag_max[k], 2.9);  // sim time, /clock at 100 Hz
    EXPECT_GE(publish_lag_max[k], lag_max[k]);
  }
  EXPECT_EQ(status->buffered, 0u);

  // ---- the merge rule: one map fed every streamed scan in stamp order (vehicle, index on ties).
  const wavog_ros::Config config =
      wavog_ros::loadConfigFile(std::string(WAVOG_SOURCE_DIR) + "/test/ros/fleet_map.yaml", nullptr);
  std::vector<std::tuple<ros::Time, std::size_t, std::uint64_t, const wavog_mapping::PlacedScan*>> all;
  for (std::size_t k = 0; k < scans.size(); ++k)
    for (const auto& m : scans[k]) all.emplace_back(m->header.stamp, k, m->index, m.get());
  std::sort(all.begin(), all.end());
  wavog::WaveletMap single(config.map);
  std::vector<float> decoded;  // a version-2 scan's ranges
  for (const auto& e : all) {
    const wavog_mapping::PlacedScan& m = *std::get<3>(e);
    ASSERT_EQ(single.integrate(wavog_fleet::placedPose(m), wavog_fleet::placedView(m, &decoded))
                  .status,
              wavog::ScanStatus::kOk);
  }
  const wavog::WaveletMap fleet = loadMap(config.map, stem + "_fleet.wmap");
  wavog::CellBox bf, bs;
  ASSERT_TRUE(fleet.bounds(0, &bf));
  ASSERT_TRUE(single.bounds(0, &bs));
  ASSERT_TRUE(bf.min_x == bs.min_x && bf.min_y == bs.min_y && bf.max_x == bs.max_x &&
              bf.max_y == bs.max_y);
  const wavog::Raster rf = fleet.exportScale(0, bf, wavog::Aggregation::kMean);
  const wavog::Raster rs = single.exportScale(0, bs, wavog::Aggregation::kMean);
  const std::size_t differ = map_compare::differingCells(rf, rs);
  const std::size_t known = map_compare::knownCells(rf);
  EXPECT_EQ(differ, 0u) << "of " << rf.log_odds.size() << " cells (" << total << " scans)";
  EXPECT_GT(known, 100000u);

  // ---- a fleet node started late catches up from map_file, the other fleet node's save_map: its
  // map is that map, cell for cell, before any scan reaches it.
  {
    Child loader, late;
    loader.pid = spawn({"rosparam", "load", std::string(WAVOG_SOURCE_DIR) + "/test/ros/fleet_map.yaml",
                        "/late/wavog_fleet"});
    int status_code = -1;
    ASSERT_EQ(waitpid(loader.pid, &status_code, 0), loader.pid);
    loader.pid = -1;
    ASSERT_TRUE(WIFEXITED(status_code) && WEXITSTATUS(status_code) == 0);
    ros::param::set("/late/wavog_fleet/map_file", stem + "_fleet.wmap");
    late.pid = spawn({WAVOG_FLEET_BIN, "__ns:=/late", "__name:=wavog_fleet"});
    ASSERT_TRUE(saveMap("/late/wavog_fleet/save_map", stem + "_late.wmap"));
  }
  const wavog::WaveletMap caught = loadMap(config.map, stem + "_late.wmap");
  wavog::CellBox bl;
  ASSERT_TRUE(caught.bounds(0, &bl));
  ASSERT_TRUE(bl.min_x == bf.min_x && bl.min_y == bf.min_y && bl.max_x == bf.max_x &&
              bl.max_y == bf.max_y);
  const wavog::Raster rl = caught.exportScale(0, bl, wavog::Aggregation::kMean);
  const std::size_t differ_late = map_compare::differingCells(rf, rl);
  EXPECT_EQ(differ_late, 0u) << "of " << rf.log_odds.size() << " cells";

  // ---- each vehicle's own map is its stream replayed alone (v1, v3; v2's map may hold a few
  // scans it integrated but never sent before SIGKILL): the mapper integrated the decoded codes,
  // as the fleet node did.
  for (const std::size_t k : {std::size_t{0}, std::size_t{2}}) {
    SCOPED_TRACE(kVehicles[k]);
    wavog::WaveletMap replayed(config.map);
    for (const auto& m : scans[k]) {
      ASSERT_EQ(replayed.integrate(wavog_fleet::placedPose(*m), wavog_fleet::placedView(*m, &decoded))
                    .status,
                wavog::ScanStatus::kOk);
    }
    const wavog::WaveletMap own = loadMap(config.map, stem + "_" + kVehicles[k] + ".wmap");
    wavog::CellBox bo, br;
    ASSERT_TRUE(own.bounds(0, &bo));
    ASSERT_TRUE(replayed.bounds(0, &br));
    ASSERT_TRUE(bo.min_x == br.min_x && bo.min_y == br.min_y && bo.max_x == br.max_x &&
                bo.max_y == br.max_y);
    const wavog::Raster ro = own.exportScale(0, bo, wavog::Aggregation::kMean);
    const wavog::Raster rr = replayed.exportScale(0, br, wavog::Aggregation::kMean);
    const std::size_t differ_own = map_compare::differingCells(ro, rr);
    EXPECT_EQ(differ_own, 0u) << "of " << ro.log_odds.size() << " cells";
  }

  // ---- ground truth: the fleet gets at least as many cells right as the best single vehicle.
  const double end = 28.0;
  const wavog::sim::World world = wavog::sim::defaultWorld(end);
  const std::size_t fleet_right = truthCellsRight(fleet, world, end);
  std::size_t best = 0;
  for (const std::string v : {"v1", "v2", "v3"}) {
    const wavog::WaveletMap m = loadMap(config.map, stem + "_" + v + ".wmap");
    const std::size_t right = truthCellsRight(m, world, end);
    std::printf("fleet test: %s gets %zu ground-truth cells right\n", v.c_str(), right);
    best = std::max(best, right);
  }
  // ---- v2's cells stay after it was killed: every cell its stream observed (its map may hold a
  // few scans more, integrated but still unsent when SIGKILL came) is observed in the fleet map.
  {
    wavog::WaveletMap streamed(config.map);
    for (const auto& m : scans[1]) {
      streamed.integrate(wavog_fleet::placedPose(*m), wavog_fleet::placedView(*m, &decoded));
    }
    wavog::CellBox b;
    ASSERT_TRUE(streamed.bounds(0, &b));
    const wavog::Raster r = streamed.exportScale(0, b, wavog::Aggregation::kMean);
    std::size_t observed = 0, kept = 0;
    for (std::int64_t y = b.min_y; y < b.max_y; ++y) {
      for (std::int64_t x = b.min_x; x < b.max_x; ++x) {
        if (!r.known[static_cast<std::size_t>((y - b.min_y) * b.width() + (x - b.min_x))]) continue;
        ++observed;
        kept += fleet.isObserved(wavog::CellIndex{x, y});
      }
    }
    EXPECT_GT(observed, 10000u);
    EXPECT_EQ(kept, observed);
  }
  std::printf("fleet test: the fleet map gets %zu right (%zu scans)\n", fleet_right, total);
  EXPECT_GE(fleet_right, best);

  const std::string prefix = "wavog_fleet_test_" + std::to_string(getpid()) + "_";
  for (const auto& e : std::filesystem::directory_iterator("/tmp")) {
    if (e.path().filename().string().rfind(prefix, 0) == 0) std::filesystem::remove(e.path());
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "fleet_system_test");
  return RUN_ALL_TESTS();
}
