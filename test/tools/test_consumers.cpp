// Consumers rostest (consumers_demo.test, consumers_johnny5.test): a bag played into the node, and
// every `map`, `map_scale_<s>` and `map_updates` message read as the navigation stack reads it:
//   amcl (map conversion): 0 is free, 100 occupied, every other value unknown;
//   costmap_2d's static layer (trinary_costmap true, lethal_cost_threshold 100,
//     unknown_cost_value -1): -1 unknown, >= 100 lethal, everything else free.
// Checked: the grids carry only 0 / 100 / -1; no update reaches outside the last full `map`
// received; after the bag, the node's final layers against wavog_offline's map of the same bag
// and YAML (the same thresholds, the same aggregation): every cell occupied there is occupied to
// both rules, at least kMinFreeShare of its free cells free; a layer subscribed to only after the
// bag's clock has stopped arrives, as do /diagnostics; ~reset publishes the reset map (same box,
// every cell unknown) while the clock is stopped. Per layer, the known cells each rule
// reads as occupied / free / unknown are printed (the figures of issue 41).
//
// Private parameters: bag, config (the YAML both use), scales (the node's publish_scales).
#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <map_msgs/OccupancyGridUpdate.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <std_srvs/Empty.h>
#include <std_srvs/Trigger.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "wavog_mapping/MapperStatus.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/ros/config.h"

namespace {

namespace fs = std::filesystem;

constexpr double kWaitSeconds = 200.0;  // wall time for the bag to play and settle
constexpr double kQuietSeconds = 6.0;   // no counter moved for this long: the bag has ended
constexpr double kMinFreeShare = 0.95;  // of the offline map's free cells, free to both rules
constexpr double kResetSeconds = 30.0;  // bound on ~reset's reset map, wall time (not a latency)
constexpr double kLateSeconds = 30.0;   // bound on a late subscriber's first message, wall time
constexpr double kFlushSeconds = 60.0;  // bound on the wait for ~flush's layers, wall time

/// How the two consumers read one value.
enum class Reading { kFree, kOccupied, kUnknown };
Reading amcl(std::int8_t v) {
  return v == 0 ? Reading::kFree : v == 100 ? Reading::kOccupied : Reading::kUnknown;
}
Reading costmap(std::int8_t v) {
  return v == -1 ? Reading::kUnknown : v >= 100 ? Reading::kOccupied : Reading::kFree;
}

struct Counts {
  std::size_t known = 0, occupied = 0, free = 0, unknown = 0;
};
template <typename Rule>
Counts countGrid(const std::vector<std::int8_t>& data, Rule rule) {
  Counts c;
  for (std::int8_t v : data) {
    if (v == -1) continue;
    ++c.known;
    const Reading r = rule(v);
    if (r == Reading::kOccupied) ++c.occupied;
    if (r == Reading::kFree) ++c.free;
    if (r == Reading::kUnknown) ++c.unknown;
  }
  return c;
}

/// What the test sees of the node's grids.
class Grids {
 public:
  Grids(ros::NodeHandle& nh, const std::vector<int>& scales) {
    subs_.push_back(nh.subscribe<nav_msgs::OccupancyGrid>(
        "/map", 10, [this](const nav_msgs::OccupancyGrid::ConstPtr& m) { onGrid(0, m); }));
    for (int s : scales) {
      subs_.push_back(nh.subscribe<nav_msgs::OccupancyGrid>(
          "/map_scale_" + std::to_string(s), 10,
          [this, s](const nav_msgs::OccupancyGrid::ConstPtr& m) { onGrid(s, m); }));
    }
    subs_.push_back(nh.subscribe("/map_updates", 100, &Grids::onUpdate, this));
  }

  nav_msgs::OccupancyGrid::ConstPtr last(int scale) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = last_.find(scale);
    return it == last_.end() ? nullptr : it->second;
  }
  std::size_t maps() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return maps_;
  }
  /// Messages received on a layer's topic (scale 0: `map`).
  std::size_t received(int scale) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = received_.find(scale);
    return it == received_.end() ? 0 : it->second;
  }
  std::size_t updates() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return updates_;
  }
  std::size_t updatesOutside() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return outside_;
  }
  std::set<int> values() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return values_;
  }
  std::size_t boxes() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return boxes_;
  }

 private:
  void onGrid(int scale, const nav_msgs::OccupancyGrid::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (std::int8_t v : m->data) values_.insert(v);
    if (scale == 0) {
      ++maps_;
      const auto& p = last_[0];
      if (!p || p->info.width != m->info.width || p->info.height != m->info.height ||
          p->info.origin.position.x != m->info.origin.position.x ||
          p->info.origin.position.y != m->info.origin.position.y) {
        ++boxes_;
      }
    }
    last_[scale] = m;
    ++received_[scale];
  }
  void onUpdate(const map_msgs::OccupancyGridUpdate::ConstPtr& u) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++updates_;
    for (std::int8_t v : u->data) values_.insert(v);
    const auto it = last_.find(0);
    const bool inside = it != last_.end() && u->x >= 0 && u->y >= 0 &&
                        static_cast<std::uint64_t>(u->x) + u->width <= it->second->info.width &&
                        static_cast<std::uint64_t>(u->y) + u->height <= it->second->info.height;
    if (!inside) {
      ++outside_;
      std::cout << "update " << u->width << " x " << u->height << " at " << u->x << ", " << u->y
                << " outside the last map ("
                << (it == last_.end() ? std::string("none")
                                      : std::to_string(it->second->info.width) + " x " +
                                            std::to_string(it->second->info.height))
                << ")\n";
    }
  }

  mutable std::mutex mutex_;
  std::map<int, nav_msgs::OccupancyGrid::ConstPtr> last_;
  std::map<int, std::size_t> received_;
  std::set<int> values_;
  std::size_t maps_ = 0, updates_ = 0, outside_ = 0, boxes_ = 0;
  std::vector<ros::Subscriber> subs_;
};

std::mutex g_mutex;
wavog_mapping::MapperStatus::ConstPtr g_status;
std::size_t g_statuses = 0;  // ~status messages received

void onStatus(const wavog_mapping::MapperStatus::ConstPtr& s) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_status = s;
  ++g_statuses;
}

std::size_t statuses() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return g_statuses;
}

/// Scans of the bag on the YAML's input topics.
std::uint64_t bagScans(const std::string& path, const wavog_ros::Config& config) {
  std::vector<std::string> topics;
  for (const auto& in : config.ros.inputs) {
    topics.push_back(in.topic[0] == '/' ? in.topic : "/" + in.topic);
  }
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  return rosbag::View(bag, rosbag::TopicQuery(topics)).size();
}

std::uint64_t handled(const wavog_mapping::MapperStatus& s) {
  std::uint64_t n = 0;
  for (const auto& in : s.inputs) {
    n += in.integrated + in.dropped_empty + in.dropped_bad_angles + in.dropped_bad_frame +
         in.dropped_tf_unavailable + in.dropped_tf_too_old + in.dropped_no_valid_beam +
         in.dropped_bad_geometry + in.dropped_out_of_extent + in.dropped_absurd_pose +
         in.dropped_bad_time + in.dropped_exception;
  }
  return n;
}

/// Compares one of the node's grids with the offline map's layer over the grid's box: every cell
/// the offline map says is occupied must be occupied to both rules; returns the share of its free
/// cells that both rules read as free.
void compareLayer(const nav_msgs::OccupancyGrid& grid, const wavog::WaveletMap& offline, int scale,
                  const wavog_ros::Config& config, const std::string& name) {
  const double cell = grid.info.resolution;
  ASSERT_NEAR(cell, std::ldexp(config.map.grid.resolution, scale), 1e-6) << name;
  const auto x0 = static_cast<std::int64_t>(std::llround(grid.info.origin.position.x / cell));
  const auto y0 = static_cast<std::int64_t>(std::llround(grid.info.origin.position.y / cell));
  const wavog::CellBox box{x0, y0, x0 + grid.info.width, y0 + grid.info.height};
  const wavog::Raster r = offline.exportScale(
      scale, box, scale == 0 ? wavog::Aggregation::kMean : config.ros.scale_aggregation);
  const std::vector<std::int8_t> expect = wavog::toOccupancyGrid(r, config.ros.grid_values);
  ASSERT_EQ(expect.size(), grid.data.size()) << name;
  std::size_t occupied = 0, occupied_missed = 0, free = 0, free_read = 0;
  for (std::size_t i = 0; i < expect.size(); ++i) {
    if (expect[i] == 100) {
      ++occupied;
      const bool both =
          amcl(grid.data[i]) == Reading::kOccupied && costmap(grid.data[i]) == Reading::kOccupied;
      occupied_missed += both ? 0 : 1;
    }
    if (expect[i] == 0) {
      ++free;
      free_read += amcl(grid.data[i]) == Reading::kFree && costmap(grid.data[i]) == Reading::kFree;
    }
  }
  std::cout << name << " against the offline map: " << occupied << " occupied cells, "
            << occupied_missed << " not occupied to both rules; " << free << " free cells, "
            << free_read << " free to both rules\n";
  EXPECT_GT(occupied, 0u) << name;
  EXPECT_EQ(occupied_missed, 0u) << name;
  EXPECT_GE(static_cast<double>(free_read), kMinFreeShare * static_cast<double>(free)) << name;
}

void printCounts(const std::string& name, const nav_msgs::OccupancyGrid& g) {
  const Counts a = countGrid(g.data, amcl);
  const Counts c = countGrid(g.data, costmap);
  std::cout << name << " (" << g.info.width << " x " << g.info.height << "): " << a.known
            << " known cells; amcl reads " << a.occupied << " occupied / " << a.free << " free / "
            << a.unknown << " unknown; costmap_2d reads " << c.occupied << " occupied / " << c.free
            << " free / " << c.unknown << " unknown\n";
}

TEST(Consumers, NavigationStackReadsThePublishedMap) {
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  std::string bag, config_path;
  std::vector<int> scales;
  ASSERT_TRUE(pnh.getParam("bag", bag));
  ASSERT_TRUE(pnh.getParam("config", config_path));
  ASSERT_TRUE(pnh.getParam("scales", scales));
  const wavog_ros::Config config = wavog_ros::loadConfigFile(config_path, nullptr);
  const fs::path dir =
      fs::temp_directory_path() / ("wavog_consumers_" + std::to_string(::getpid()));
  fs::create_directories(dir);

  Grids grids(nh, scales);
  ros::Subscriber status_sub = nh.subscribe("/wavog_mapping/status", 10, onStatus);

  // The offline map while the bag plays.
  const std::string cmd = std::string(WAVOG_OFFLINE) + " --quiet -c " + config_path + " -o " +
                          (dir / "offline").string() + " " + bag;
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  wavog::WaveletMap offline(config.map);
  offline.load((dir / "offline" / "map.wavog").string());

  // Until every scan of the bag is handled, then quiet: the bag has ended.
  const std::uint64_t n = bagScans(bag, config);
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kWaitSeconds);
  std::uint64_t seen = 0;
  ros::WallTime last_change = ros::WallTime::now();
  while (ros::ok() && ros::WallTime::now() < deadline) {
    std::uint64_t now_handled = 0;
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      if (g_status) now_handled = handled(*g_status);
    }
    if (now_handled != seen) last_change = ros::WallTime::now();
    seen = now_handled;
    if (seen >= n && (ros::WallTime::now() - last_change).toSec() > 1.0) break;
    if (seen > 0 && (ros::WallTime::now() - last_change).toSec() > kQuietSeconds) break;
    ros::WallDuration(0.1).sleep();
  }
  std::cout << "bag: " << n << " scans, the node handled " << seen << "\n";
  ASSERT_GT(seen, 0u);

  // The end of the input: every layer once more, now.
  ros::ServiceClient flush = nh.serviceClient<std_srvs::Trigger>("/wavog_mapping/flush");
  std_srvs::Trigger trigger;
  std::vector<int> layers{0};
  layers.insert(layers.end(), scales.begin(), scales.end());
  std::map<int, std::size_t> before;
  for (int s : layers) before[s] = grids.received(s);
  const std::size_t statuses_before = statuses();
  ASSERT_TRUE(flush.call(trigger));
  // Every layer and the status published by the flush have arrived (however long a busy machine
  // takes).
  const ros::WallTime flush_deadline = ros::WallTime::now() + ros::WallDuration(kFlushSeconds);
  const auto flushed = [&] {
    return statuses() > statuses_before && std::all_of(layers.begin(), layers.end(), [&](int s) {
             return grids.received(s) > before[s];
           });
  };
  while (!flushed() && ros::WallTime::now() < flush_deadline) ros::WallDuration(0.05).sleep();
  ASSERT_TRUE(flushed()) << "the layers and status of ~flush did not arrive within "
                         << kFlushSeconds << " s";
  // The node placed the scans as wavog_offline did, however busy the host: as many integrated,
  // as many without motion compensation (those waiting for tf when the bag ended included).
  std::ifstream summary_file(dir / "offline" / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  std::uint64_t integrated = 0, fallbacks = 0;
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    for (const auto& in : g_status->inputs) {
      std::cout << in.topic << ": " << in.received << " received, " << in.integrated
                << " integrated (" << in.integrated_latest_tf << " by the latest tf, "
                << in.motion_fallbacks << " without motion compensation), " << in.lost << " lost\n";
      integrated += in.integrated;
      fallbacks += in.motion_fallbacks;
    }
  }
  EXPECT_EQ(integrated, summary["scans_integrated"].get<std::uint64_t>());
  EXPECT_EQ(fallbacks, summary["motion_fallbacks"].get<std::uint64_t>());

  const std::set<int> values = grids.values();
  std::string seen_values;
  for (int v : values) seen_values += " " + std::to_string(v);
  std::cout << "values in the grids and updates:" << seen_values << "; " << grids.maps()
            << " maps (" << grids.boxes() << " boxes), " << grids.updates() << " updates, "
            << grids.updatesOutside() << " outside the last map\n";
  if (config.ros.grid_values.trinary) {
    for (int v : values) EXPECT_TRUE(v == -1 || v == 0 || v == 100) << "value " << v;
  }
  EXPECT_GT(grids.updates(), 0u);
  EXPECT_EQ(grids.updatesOutside(), 0u);

  const auto map = grids.last(0);
  ASSERT_TRUE(map);
  printCounts("map", *map);
  compareLayer(*map, offline, 0, config, "map");
  for (int s : scales) {
    const auto layer = grids.last(s);
    ASSERT_TRUE(layer) << "map_scale_" << s;
    printCounts("map_scale_" + std::to_string(s), *layer);
    compareLayer(*layer, offline, s, config, "map_scale_" + std::to_string(s));
  }

  // After the bag (its clock stopped): a layer and /diagnostics reach a new subscriber.
  bool late_layer = false, diagnostics = false;
  ros::Subscriber late = nh.subscribe<nav_msgs::OccupancyGrid>(
      "/map_scale_" + std::to_string(scales.back()), 1,
      [&late_layer](const nav_msgs::OccupancyGrid::ConstPtr&) { late_layer = true; });
  ros::Subscriber diag = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 1,
      [&diagnostics](const diagnostic_msgs::DiagnosticArray::ConstPtr&) { diagnostics = true; });
  const ros::WallTime late_deadline = ros::WallTime::now() + ros::WallDuration(kLateSeconds);
  while ((!late_layer || !diagnostics) && ros::WallTime::now() < late_deadline) {
    ros::WallDuration(0.05).sleep();
  }
  EXPECT_TRUE(late_layer) << "map_scale_" << scales.back() << " after the bag";
  EXPECT_TRUE(diagnostics) << "/diagnostics after the bag";

  // ~reset: the reset map (the same box, every cell unknown) within kResetSeconds.
  ros::ServiceClient reset = nh.serviceClient<std_srvs::Empty>("/wavog_mapping/reset");
  std_srvs::Empty empty;
  const ros::WallTime t_reset = ros::WallTime::now();
  ASSERT_TRUE(reset.call(empty));
  bool reset_seen = false;
  while (!reset_seen && (ros::WallTime::now() - t_reset).toSec() < kResetSeconds) {
    const auto m = grids.last(0);
    reset_seen = m && m->info.width == map->info.width && m->info.height == map->info.height &&
                 std::all_of(m->data.begin(), m->data.end(), [](std::int8_t v) { return v == -1; });
    ros::WallDuration(0.01).sleep();
  }
  EXPECT_TRUE(reset_seen) << "no reset map within " << kResetSeconds << " s of wall time";
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_consumers");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}
