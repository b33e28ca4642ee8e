// Region shards over ROS (issue 36; test/fleet_shards.test): the test streams the placed scans of
// three simulated car-park vehicles (as their mappers would, on /v<k>/fleet_scans) to one fleet
// node without a region (/all) and to two region shards (/shard_a, /shard_b) on their own loopback
// addresses. Checks: the shards' saved maps together equal the unsharded one, cell for cell (every
// finest cell and every scale, as floats); the window /v1/fleet_map equals the unsharded fleet map
// inside it (and its updates apply to it); wavog_site's site_map_scale_3 equals the unsharded
// map_scale_3; a fourth vehicle 1 km east of the car park, outside every region, is counted by
// each shard (outside_region) and mapped by none (only by the unsharded node); a shard restarted
// from its own ~save_map holds that map exactly. Prints the bytes of a vehicle's window.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <map_msgs/OccupancyGridUpdate.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/master.h>
#include <ros/ros.h>
#include <ros/serialization.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "fleet_test_support.h"
#include "map_compare.h"
#include "wavog_mapping/FleetStatus.h"
#include "wavog_mapping/PlacedScan.h"
#include "wavog_mapping/SaveMap.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/ros/config.h"
#include "wavog_mapping/sim/laser_sim.h"
#include "wavog_mapping/sim/world.h"

namespace {

constexpr double kDuration = 5.0;  // s of each vehicle's drive
const std::vector<std::string> kNodes = {"/all", "/shard_a", "/shard_b"};
constexpr double kFarEast = 1000.0;  // m: v4 is v1 this far east

using fleet_test::spawn;  // every child here gets a host of its own (a loopback address)
using fleet_test::stop;

/// One placed scan as a mapper streams it (fleet_stream.cpp fills the same fields).
struct Streamed {
  double t = 0.0;  // s after the start
  int vehicle = 0;
  wavog_mapping::PlacedScan msg;
};

std::vector<Streamed> fleetScans(int vehicles) {
  std::vector<Streamed> out;
  const wavog::sim::World base = wavog::sim::defaultWorld(kDuration);
  for (int k = 0; k < vehicles; ++k) {
    const wavog::sim::World w = wavog::sim::fleetMember(base, k, vehicles);
    wavog::sim::ScanSimulator sim(w, 11 + static_cast<std::uint64_t>(k));
    wavog::sim::SimScan s;
    std::uint64_t index = 0;
    while (sim.next(&s)) {
      const auto& laser = w.vehicle.lasers[static_cast<std::size_t>(s.laser)];
      Streamed p;
      p.t = s.stamp;
      p.vehicle = k;
      p.msg.version = 1;
      p.msg.vehicle = "v" + std::to_string(k + 1);
      p.msg.input = laser.topic;
      p.msg.index = index++;
      p.msg.header.frame_id = "map";
      p.msg.x = p.msg.start_x = p.msg.end_x = s.sensor_pose.x;
      p.msg.y = p.msg.start_y = p.msg.end_y = s.sensor_pose.y;
      p.msg.theta = p.msg.start_theta = p.msg.end_theta = s.sensor_pose.theta;
      const wavog::ScanView view = s.view(laser);
      p.msg.ranges.assign(view.ranges, view.ranges + view.count);
      p.msg.angle_min = view.angle_min;
      p.msg.angle_increment = view.angle_increment;
      p.msg.range_min = view.range_min;
      p.msg.range_max = view.range_max;
      p.msg.period = 1.0 / laser.rate_hz;
      out.push_back(std::move(p));
    }
  }
  // v4: v1's scans, placed 1 km further east.
  const std::size_t n = out.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (out[i].vehicle != 0) continue;
    Streamed p = out[i];
    p.vehicle = 3;
    p.msg.vehicle = "v4";
    p.msg.x += kFarEast;
    p.msg.start_x += kFarEast;
    p.msg.end_x += kFarEast;
    out.push_back(std::move(p));
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const Streamed& a, const Streamed& b) { return a.t < b.t; });
  return out;
}

template <typename M>
struct Latest {
  std::mutex mutex;
  typename M::ConstPtr msg;
  std::size_t count = 0, bytes = 0;
  void operator()(const typename M::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    msg = m;
    ++count;
    bytes += ros::serialization::serializationLength(*m);
  }
  typename M::ConstPtr get() {
    std::lock_guard<std::mutex> lock(mutex);
    return msg;
  }
};

/// wavog_site's latest "site" status in /diagnostics, as key -> value.
struct SiteDiagnostics {
  std::mutex mutex;
  std::map<std::string, std::string> values;
  void operator()(const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
    for (const auto& st : m->status) {
      if (st.name.find("wavog_site") == std::string::npos) continue;
      std::lock_guard<std::mutex> lock(mutex);
      values.clear();
      for (const auto& kv : st.values) values[kv.key] = kv.value;
    }
  }
  std::string get(const std::string& key) {
    std::lock_guard<std::mutex> lock(mutex);
    auto it = values.find(key);
    return it == values.end() ? std::string("(none)") : it->second;
  }
};

bool saveMap(const std::string& service, const std::string& path) {
  wavog_mapping::SaveMap srv;
  srv.request.path = path;
  if (!ros::service::waitForService(service, ros::Duration(20.0))) return false;
  return ros::service::call(service, srv) && srv.response.success;
}

/// The value of grid `g` at the cell of lattice index (ix, iy); -1 outside it.
int cellOf(const nav_msgs::OccupancyGrid& g, std::int64_t ix, std::int64_t iy) {
  const double res = g.info.resolution;
  const auto x0 = static_cast<std::int64_t>(std::llround(g.info.origin.position.x / res));
  const auto y0 = static_cast<std::int64_t>(std::llround(g.info.origin.position.y / res));
  const std::int64_t x = ix - x0, y = iy - y0;
  if (x < 0 || y < 0 || x >= g.info.width || y >= g.info.height) return -1;
  return g.data[static_cast<std::size_t>(y * g.info.width + x)];
}

/// Cells of `a` that differ from `b` at the same place, and the known ones; only those of lattice
/// indices within `only` when it is not empty.
std::pair<std::size_t, std::size_t> gridDiff(const nav_msgs::OccupancyGrid& a,
                                             const nav_msgs::OccupancyGrid& b,
                                             const wavog::CellBox& only = wavog::CellBox{}) {
  std::size_t differ = 0, known = 0;
  const double res = a.info.resolution;
  const auto x0 = static_cast<std::int64_t>(std::llround(a.info.origin.position.x / res));
  const auto y0 = static_cast<std::int64_t>(std::llround(a.info.origin.position.y / res));
  for (std::uint32_t y = 0; y < a.info.height; ++y) {
    for (std::uint32_t x = 0; x < a.info.width; ++x) {
      const std::int64_t ix = x0 + x, iy = y0 + y;
      if (!only.empty() &&
          (ix < only.min_x || ix >= only.max_x || iy < only.min_y || iy >= only.max_y)) {
        continue;
      }
      const int v = a.data[y * a.info.width + x];
      known += v != -1;
      differ += v != cellOf(b, x0 + x, y0 + y);
    }
  }
  return {differ, known};
}

TEST(FleetShards, ShardsWindowsAndSiteLayersEqualTheOneFleetMap) {
  ros::NodeHandle nh;
  wavog_ros::Config config = wavog_ros::loadConfigFile(
      std::string(WAVOG_SOURCE_DIR) + "/test/ros/fleet_shard.yaml", nullptr);
  const std::vector<Streamed> scans = fleetScans(3);
  ASSERT_GT(scans.size(), 1500u);
  std::size_t v4_scans = 0;
  for (const Streamed& s : scans) v4_scans += s.vehicle == 3;

  std::vector<ros::Publisher> pubs;
  for (int k = 1; k <= 4; ++k) {
    pubs.push_back(
        nh.advertise<wavog_mapping::PlacedScan>("/v" + std::to_string(k) + "/fleet_scans", 5000));
  }
  Latest<wavog_mapping::FleetStatus> status[3];
  std::vector<ros::Subscriber> subs;
  for (int i = 0; i < 3; ++i) {
    subs.push_back(nh.subscribe<wavog_mapping::FleetStatus>(
        kNodes[static_cast<std::size_t>(i)] + "/wavog_fleet/fleet_status", 10,
        boost::ref(status[i])));
  }
  Latest<nav_msgs::OccupancyGrid> all_map, all_scale, site_scale, window;
  Latest<map_msgs::OccupancyGridUpdate> window_update;
  subs.push_back(nh.subscribe<nav_msgs::OccupancyGrid>("/all/map", 2, boost::ref(all_map)));
  subs.push_back(
      nh.subscribe<nav_msgs::OccupancyGrid>("/all/map_scale_3", 2, boost::ref(all_scale)));
  subs.push_back(
      nh.subscribe<nav_msgs::OccupancyGrid>("/site_map_scale_3", 2, boost::ref(site_scale)));
  subs.push_back(nh.subscribe<nav_msgs::OccupancyGrid>("/v1/fleet_map", 2, boost::ref(window)));
  const std::size_t window_sub = subs.size() - 1;
  // shard_a's window of v1 (its region only), in its private namespace.
  Latest<nav_msgs::OccupancyGrid> shard_window;
  subs.push_back(nh.subscribe<nav_msgs::OccupancyGrid>("/shard_a/wavog_fleet/v1/fleet_map", 2,
                                                       boost::ref(shard_window)));
  subs.push_back(nh.subscribe<map_msgs::OccupancyGridUpdate>("/v1/fleet_map_updates", 100,
                                                             boost::ref(window_update)));
  SiteDiagnostics site_diag;
  subs.push_back(
      nh.subscribe<diagnostic_msgs::DiagnosticArray>("/diagnostics", 50, boost::ref(site_diag)));
  ros::AsyncSpinner spinner(2);
  spinner.start();

  // Every fleet node subscribed to every vehicle.
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(40.0);
  while (ros::WallTime::now() < deadline) {
    bool all = true;
    for (const auto& p : pubs) all = all && p.getNumSubscribers() >= 3;
    if (all) break;
    ros::WallDuration(0.1).sleep();
  }
  for (const auto& p : pubs) ASSERT_GE(p.getNumSubscribers(), 3u) << p.getTopic();
  ros::WallDuration(0.5).sleep();

  // The vehicles' streams at their real pace, stamped from now.
  const ros::Time start = ros::Time::now() + ros::Duration(0.2);
  const ros::WallTime wall_start = ros::WallTime::now() + ros::WallDuration(0.2);
  for (const Streamed& s : scans) {
    const ros::WallTime at = wall_start + ros::WallDuration(s.t);
    const ros::WallTime now = ros::WallTime::now();
    if (now < at) (at - now).sleep();
    auto m = boost::make_shared<wavog_mapping::PlacedScan>(s.msg);
    m->header.stamp = start + ros::Duration(s.t);
    pubs[static_cast<std::size_t>(s.vehicle)].publish(m);
  }

  // Every node integrated every scan, none late.
  const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(30.0);
  bool done = false;
  while (!done && ros::WallTime::now() < until) {
    done = true;
    for (auto& st : status) {
      const auto m = st.get();
      std::uint64_t integrated = 0;
      if (m) {
        for (const auto& v : m->vehicles) integrated += v.integrated;
      }
      done = done && integrated == scans.size();
    }
    if (!done) ros::WallDuration(0.2).sleep();
  }
  ASSERT_TRUE(done) << "not every fleet node integrated the " << scans.size() << " scans";
  for (int i = 0; i < 3; ++i) {
    for (const auto& v : status[i].get()->vehicles) {
      EXPECT_EQ(v.integrated_late, 0u) << kNodes[static_cast<std::size_t>(i)] << " " << v.vehicle;
      EXPECT_EQ(v.lost, 0u) << kNodes[static_cast<std::size_t>(i)] << " " << v.vehicle;
      // v4 is outside every region: each shard counts all its scans, and no other vehicle's
      // latest scan (all in the car park) missed both shards.
      if (i > 0 && v.vehicle == "/v4") {
        EXPECT_EQ(v.outside_region, v4_scans) << kNodes[static_cast<std::size_t>(i)];
        EXPECT_FALSE(v.in_region);
      }
      if (i == 0) {
        EXPECT_EQ(v.outside_region, 0u);  // no region
      }
    }
  }
  ASSERT_EQ(status[0].get()->vehicles.size(), 4u);

  // wavog_site's site-wide figures: v4 outside every region, all its scans mapped by no shard,
  // no layer refused.
  const std::string v4_count = std::to_string(v4_scans);
  const ros::WallTime diag_until = ros::WallTime::now() + ros::WallDuration(10.0);
  while (ros::WallTime::now() < diag_until &&
         site_diag.get("scans mapped by no shard (at most)") != v4_count) {
    ros::WallDuration(0.2).sleep();
  }
  EXPECT_EQ(site_diag.get("scans mapped by no shard (at most)"), v4_count);
  EXPECT_EQ(site_diag.get("vehicles outside every region"), "1");
  // "/v4", or "/v4 (silent)" once it is stale in both shards (5 s after its last scan).
  EXPECT_EQ(site_diag.get("outside every region").rfind("/v4", 0), 0u)
      << site_diag.get("outside every region");
  EXPECT_EQ(site_diag.get("overlapping regions"), "0");  // the regions share an edge only
  EXPECT_EQ(site_diag.get("shard restarts"), "0");
  EXPECT_EQ(site_diag.get("layers refused: bad layer"), "0");
  EXPECT_EQ(site_diag.get("layers refused: shards disagree"), "0");
  EXPECT_EQ(site_diag.get("layers refused: over max_cells"), "0");
  EXPECT_EQ(site_diag.get("topics without a publisher"), "0");

  // ---- the shard rule: the saved maps, as floats, every cell at every scale.
  const std::string stem = "/tmp/wavog_fleet_shards_" + std::to_string(getpid());
  wavog::MapParams params = config.map;
  std::vector<wavog::WaveletMap> maps;
  for (const std::string& node : kNodes) {
    ASSERT_TRUE(saveMap(node + "/wavog_fleet/save_map", stem + node.substr(1) + ".wmap")) << node;
    maps.emplace_back(params);
    maps.back().load(stem + node.substr(1) + ".wmap");
  }
  const wavog::WaveletMap& whole = maps[0];
  const int L = params.grid.block_levels;
  const std::int64_t split = 6;  // blocks: x = 38.4 m
  std::size_t observed = 0;
  // The regions' union, blocks [-10, 22) x [-10, 16) (fleet_shards.test); v4's cells lie east of
  // it, in the unsharded map only.
  for (int s = 0; s <= L; ++s) {
    const wavog::CellBox box{-10LL << (L - s), -10LL << (L - s), 22LL << (L - s), 16LL << (L - s)};
    const wavog::Raster w = whole.exportScale(s, box, wavog::Aggregation::kMean);
    const wavog::Raster a = maps[1].exportScale(s, box, wavog::Aggregation::kMean);
    const wavog::Raster b = maps[2].exportScale(s, box, wavog::Aggregation::kMean);
    const std::int64_t split_s = split << (L - s);
    std::size_t differ = 0;
    for (std::int64_t y = 0; y < box.height(); ++y) {
      for (std::int64_t x = 0; x < box.width(); ++x) {
        const auto i = static_cast<std::size_t>(y * box.width() + x);
        const wavog::Raster& owner = box.min_x + x < split_s ? a : b;
        const wavog::Raster& other = box.min_x + x < split_s ? b : a;
        if (s == 0) observed += w.known[i];
        differ += owner.known[i] != w.known[i] ||
                  std::memcmp(&owner.log_odds[i], &w.log_odds[i], sizeof(float)) != 0 ||
                  other.known[i];
      }
    }
    EXPECT_EQ(differ, 0u) << "scale " << s << ": cells that differ of " << w.log_odds.size();
  }
  EXPECT_GT(observed, 100000u);
  // v4's cells: in the unsharded map, in no shard.
  const wavog::CellBox east = whole.boxAround(kFarEast - 5.0, 0.0, kFarEast + 75.0, 34.0, 0);
  EXPECT_GT(whole.exportScale(0, east, wavog::Aggregation::kMean).log_odds.size(), 0u);
  std::size_t east_known = 0;
  for (std::uint8_t k : whole.exportScale(0, east, wavog::Aggregation::kMean).known)
    east_known += k;
  EXPECT_GT(east_known, 10000u);
  wavog::CellBox shard_box;
  for (int i = 1; i <= 2; ++i) {
    ASSERT_TRUE(maps[static_cast<std::size_t>(i)].bounds(0, &shard_box));
    EXPECT_LE(shard_box.max_x, 22LL << L) << kNodes[static_cast<std::size_t>(i)];
  }
  EXPECT_GT(maps[1].stats(true).observed_cells, 10000u);  // both shards hold a real part
  EXPECT_GT(maps[2].stats(true).observed_cells, 10000u);

  // ---- the layers published after the last scan: window, site layer.
  const ros::Time after = ros::Time::now();
  const ros::WallTime layers_until = ros::WallTime::now() + ros::WallDuration(20.0);
  auto fresh = [&](auto& latest) {
    const auto m = latest.get();
    return m && m->header.stamp > after;
  };
  // The site layer's stamp is its oldest shard layer's: after `after`, every part is final.
  while (ros::WallTime::now() < layers_until &&
         !(fresh(all_map) && fresh(all_scale) && fresh(window) && fresh(site_scale))) {
    ros::WallDuration(0.1).sleep();
  }
  ASSERT_TRUE(fresh(all_map) && fresh(all_scale) && fresh(window) && fresh(site_scale));
  const auto win = window.get();
  const auto [window_differ, window_known] = gridDiff(*win, *all_map.get());
  EXPECT_EQ(window_differ, 0u) << "of " << win->data.size();
  EXPECT_GT(window_known, 1000u);
  // 8 m each side of v1's cell at 10 cm: 2 x 80 + 1 cells wherever v1 is in its cell (issue 42:
  // 160 to 162 before).
  EXPECT_EQ(win->info.width, 161u);
  EXPECT_EQ(win->info.height, 161u);
  const auto site = site_scale.get();
  const auto scale = all_scale.get();
  const auto [site_differ, site_known] = gridDiff(*site, *scale);
  // Within the regions (v4's cells, east of them, are the unsharded node's only).
  const auto [scale_differ, scale_known] =
      gridDiff(*scale, *site, wavog::CellBox{-10LL << 3, -10LL << 3, 22LL << 3, 16LL << 3});
  EXPECT_EQ(site_differ, 0u) << "of " << site->data.size();
  EXPECT_EQ(scale_differ, 0u) << "of " << scale->data.size();
  EXPECT_GT(site_known, 1000u);
  EXPECT_EQ(site_known, scale_known);
  std::printf(
      "window /v1/fleet_map: %u x %u cells, %zu messages %zu bytes; updates %zu messages "
      "%zu bytes; streamed %zu scans in %.1f s\n",
      win->info.width, win->info.height, window.count, window.bytes, window_update.count,
      window_update.bytes, scans.size(), kDuration);
  EXPECT_GT(window_update.count, 0u);
  // A shard's window: its own topic (/v1/fleet_map has the unsharded node alone), its region's
  // cells only, each the fleet map's.
  EXPECT_EQ(subs[window_sub].getNumPublishers(), 1u) << "publishers of /v1/fleet_map";
  const ros::WallTime shard_until = ros::WallTime::now() + ros::WallDuration(10.0);
  while (ros::WallTime::now() < shard_until && !fresh(shard_window)) {
    ros::WallDuration(0.1).sleep();
  }
  ASSERT_TRUE(fresh(shard_window));
  const auto sw = shard_window.get();
  const auto [shard_differ, shard_known] = gridDiff(*sw, *all_map.get());
  EXPECT_EQ(shard_differ, 0u) << "of " << sw->data.size();
  const auto [east_differ, east_known_cells] =
      gridDiff(*sw, *all_map.get(), wavog::CellBox{384, -1000000, 1000000, 1000000});
  EXPECT_EQ(east_known_cells, 0u) << "shard_a's window holds cells east of its region";
  std::printf("shard_a's window of v1: %zu known cells\n", shard_known);

  // ---- v4 goes silent (stale in both shards): wavog_site keeps it listed (issue 42: it dropped
  // out of /diagnostics), marked silent, and its count stays.
  const ros::WallTime silent_until = ros::WallTime::now() + ros::WallDuration(20.0);
  while (ros::WallTime::now() < silent_until &&
         site_diag.get("outside every region") != "/v4 (silent)") {
    ros::WallDuration(0.2).sleep();
  }
  for (int i = 1; i <= 2; ++i) {
    for (const auto& v : status[i].get()->vehicles) {
      if (v.vehicle == "/v4") EXPECT_TRUE(v.stale) << kNodes[static_cast<std::size_t>(i)];
    }
  }
  EXPECT_EQ(site_diag.get("outside every region"), "/v4 (silent)");
  EXPECT_EQ(site_diag.get("vehicles outside every region"), "1");
  EXPECT_EQ(site_diag.get("scans mapped by no shard (at most)"), v4_count);

  // ---- a shard restarts and catches up from its own ~save_map (map_file): its map is that map,
  // cell for cell, before any scan reaches it.
  {
    const std::string saved = stem + "shard_b.wmap";
    const pid_t loader =
        spawn({"rosparam", "load", std::string(WAVOG_SOURCE_DIR) + "/test/ros/fleet_shard.yaml",
               "/restarted/wavog_fleet"},
              "127.0.0.6");
    int code = -1;
    ASSERT_EQ(waitpid(loader, &code, 0), loader);
    ASSERT_TRUE(WIFEXITED(code) && WEXITSTATUS(code) == 0);
    ros::param::set("/restarted/wavog_fleet/fleet_region",
                    std::vector<double>{38.4, -64.0, 140.8, 102.4});
    ros::param::set("/restarted/wavog_fleet/map_file", saved);
    const pid_t restarted =
        spawn({WAVOG_FLEET_BIN, "__ns:=/restarted", "__name:=wavog_fleet"}, "127.0.0.4");
    const bool ok = saveMap("/restarted/wavog_fleet/save_map", stem + "restarted.wmap");
    stop(restarted);
    ASSERT_TRUE(ok);
    wavog::WaveletMap again(params);
    again.load(stem + "restarted.wmap");
    wavog::CellBox ba, bb;
    ASSERT_TRUE(maps[2].bounds(0, &bb));
    ASSERT_TRUE(again.bounds(0, &ba));
    ASSERT_TRUE(ba.min_x == bb.min_x && ba.min_y == bb.min_y && ba.max_x == bb.max_x &&
                ba.max_y == bb.max_y);
    const wavog::Raster ra = again.exportScale(0, ba, wavog::Aggregation::kMean);
    const wavog::Raster rb = maps[2].exportScale(0, bb, wavog::Aggregation::kMean);
    const std::size_t differ = map_compare::differingCells(ra, rb);
    EXPECT_EQ(differ, 0u) << "of " << ra.log_odds.size();
  }
  for (const std::string& name : {"all", "shard_a", "shard_b", "restarted"}) {
    for (const std::string& suffix : {".wmap", "_s0.pgm", "_s0.yaml", "_s3.pgm", "_s3.yaml"}) {
      std::remove((stem + name + suffix).c_str());
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_fleet_shards");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
