// Integration test, run against the node (mapping_node.test) and the nodelet
// (mapping_nodelet.test): static tf, four synthetic scanners in a known room; asserts every
// published layer's frame, resolution, size, origin, a known occupied, free and unknown cell, the
// status counters, and map_metadata and dynamic_map beside `map`.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <map_msgs/OccupancyGridUpdate.h>
#include <nav_msgs/GetMap.h>
#include <nav_msgs/MapMetaData.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <atomic>
#include <map>
#include <mutex>
#include <thread>

#include "room.h"
#include "wavog_mapping/MapperStatus.h"

namespace {

/// Expected geometry (test parameters: resolution 0.1, block_levels 6, scales 2 3 4): the room
/// touches blocks -1 and 0 on each axis, [-6.4, 6.4)^2, but a layer covers only the room.
constexpr double kResolution = 0.1;
constexpr double kExtent = 12.8;

class Recorder {
 public:
  void onGrid(const std::string& topic, const nav_msgs::OccupancyGrid::ConstPtr& g) {
    std::lock_guard<std::mutex> lock(mutex_);
    grids_[topic] = g;
  }
  void onStatus(const wavog_mapping::MapperStatus::ConstPtr& s) {
    std::lock_guard<std::mutex> lock(mutex_);
    status_ = s;
  }
  nav_msgs::OccupancyGrid::ConstPtr grid(const std::string& topic) {
    std::lock_guard<std::mutex> lock(mutex_);
    return grids_[topic];
  }
  wavog_mapping::MapperStatus::ConstPtr status() {
    std::lock_guard<std::mutex> lock(mutex_);
    return status_;
  }
  void onUpdate(const map_msgs::OccupancyGridUpdate::ConstPtr& u) {
    std::lock_guard<std::mutex> lock(mutex_);
    update_ = u;
    update_grid_ = grids_["map"];  // the full grid the update refers to
  }
  void update(map_msgs::OccupancyGridUpdate::ConstPtr* u, nav_msgs::OccupancyGrid::ConstPtr* g) {
    std::lock_guard<std::mutex> lock(mutex_);
    *u = update_;
    *g = update_grid_;
  }
  void onDiagnostics(const diagnostic_msgs::DiagnosticArray::ConstPtr& d) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& s : d->status) diagnostics_[s.name] = s;
  }
  std::map<std::string, diagnostic_msgs::DiagnosticStatus> diagnostics() {
    std::lock_guard<std::mutex> lock(mutex_);
    return diagnostics_;
  }

 private:
  std::mutex mutex_;
  std::map<std::string, nav_msgs::OccupancyGrid::ConstPtr> grids_;
  wavog_mapping::MapperStatus::ConstPtr status_;
  map_msgs::OccupancyGridUpdate::ConstPtr update_;
  nav_msgs::OccupancyGrid::ConstPtr update_grid_;
  std::map<std::string, diagnostic_msgs::DiagnosticStatus> diagnostics_;
};

Recorder* g_recorder = nullptr;
std::mutex g_metadata_mutex;
nav_msgs::MapMetaData::ConstPtr g_metadata;

/// True once the layer shows the room: with forgetting (gamma 0.3) a free cell needs a few scans
/// to fall below 35.
bool layerReady(const nav_msgs::OccupancyGrid::ConstPtr& g) {
  if (!g || g->info.width == 0) return false;
  const int free_value = room::cellAt(*g, room::kFreeX, room::kFreeY);
  return room::cellAt(*g, room::kOccX, room::kOccY) > 65 && free_value >= 0 && free_value < 35;
}

nav_msgs::OccupancyGrid::ConstPtr waitForLayer(const std::string& topic, double timeout) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < end) {
    auto g = g_recorder->grid(topic);
    if (layerReady(g)) return g;
    ros::WallDuration(0.05).sleep();
  }
  return g_recorder->grid(topic);
}

void checkLayer(const std::string& topic, int scale) {
  SCOPED_TRACE(topic);
  const auto g = waitForLayer(topic, 30.0);
  ASSERT_TRUE(g) << "nothing received on " << topic;
  const double res = kResolution * (1 << scale);
  EXPECT_EQ(g->header.frame_id, "map");
  EXPECT_NEAR(g->info.resolution, res, 1e-6);
  // The grid covers what was observed, the room (7.9 m x 5.9 m) and the occupied band of its
  // walls, in whole cells of the layer: not the 12.8 m blocks that hold it.
  const double x0 = g->info.origin.position.x, y0 = g->info.origin.position.y;
  const double w = g->info.width * res, h = g->info.height * res;
  EXPECT_LE(x0, -room::kHalfX + 1e-6);
  EXPECT_GE(x0, -room::kHalfX - 0.1 - res - 1e-6);
  EXPECT_LE(y0, -room::kHalfY + 1e-6);
  EXPECT_GE(y0, -room::kHalfY - 0.1 - res - 1e-6);
  EXPECT_GE(x0 + w, room::kHalfX - 1e-6);
  EXPECT_LE(x0 + w, room::kHalfX + 0.1 + res + 1e-6);
  EXPECT_GE(y0 + h, room::kHalfY - 1e-6);
  EXPECT_LE(y0 + h, room::kHalfY + 0.1 + res + 1e-6);
  EXPECT_LT(w, kExtent);
  EXPECT_EQ(g->info.origin.orientation.w, 1.0);
  ASSERT_EQ(g->data.size(), static_cast<std::size_t>(g->info.width) * g->info.height);
  EXPECT_GT(room::cellAt(*g, room::kOccX, room::kOccY), 65) << "wall cell not occupied";
  const int free_value = room::cellAt(*g, room::kFreeX, room::kFreeY);
  EXPECT_GE(free_value, 0) << "free cell unknown";
  EXPECT_LT(free_value, 35) << "free cell not free";
  EXPECT_EQ(room::cellAt(*g, room::kUnkX, room::kUnkY), -2) << "grid reaches beyond the room";
  for (std::int8_t v : g->data) {
    ASSERT_TRUE(v == -1 || (v >= 0 && v <= 100)) << static_cast<int>(v);
  }
}

TEST(MappingSystem, FinestLayer) { checkLayer("map", 0); }
TEST(MappingSystem, Scale2) { checkLayer("map_scale_2", 2); }
TEST(MappingSystem, Scale3) { checkLayer("map_scale_3", 3); }
TEST(MappingSystem, Scale4) { checkLayer("map_scale_4", 4); }

// The cells' equality with `map` is tested where the map stands still (test/services.test,
// test/fleet_map_services.test); here the scans go on, the geometry stays.
TEST(MappingSystem, MapMetadataAndDynamicMapBesideMap) {
  ASSERT_TRUE(layerReady(waitForLayer("map", 30.0)));
  nav_msgs::OccupancyGrid::ConstPtr g;
  nav_msgs::MapMetaData::ConstPtr meta;
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(10.0);
  while (ros::ok() && ros::WallTime::now() < end) {
    g = g_recorder->grid("map");
    {
      std::lock_guard<std::mutex> lock(g_metadata_mutex);
      meta = g_metadata;
    }
    if (meta && meta->map_load_time == g->info.map_load_time) break;
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_TRUE(meta) << "nothing on map_metadata";
  EXPECT_EQ(meta->map_load_time, g->info.map_load_time) << "map_metadata not sent with map";
  EXPECT_EQ(room::geometry(*meta), room::geometry(g->info));

  nav_msgs::GetMap srv;
  ASSERT_TRUE(ros::service::call("dynamic_map", srv));
  const nav_msgs::OccupancyGrid& served = srv.response.map;
  EXPECT_EQ(served.header.frame_id, "map");
  EXPECT_EQ(room::geometry(served.info), room::geometry(g->info));
  EXPECT_GT(room::cellAt(served, room::kOccX, room::kOccY), 65);
}

TEST(MappingSystem, StatusCounters) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(30.0);
  wavog_mapping::MapperStatus::ConstPtr s;
  while (ros::ok() && ros::WallTime::now() < end) {
    s = g_recorder->status();
    bool all = s && s->inputs.size() == 4;
    for (std::size_t i = 0; all && i < s->inputs.size(); ++i) all = s->inputs[i].integrated >= 5;
    if (all) break;
    ros::WallDuration(0.05).sleep();
  }
  ASSERT_TRUE(s);
  ASSERT_EQ(s->inputs.size(), 4u);
  EXPECT_EQ(s->header.frame_id, "map");
  std::uint64_t integrated = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    const auto& in = s->inputs[i];
    SCOPED_TRACE(in.topic);
    EXPECT_EQ(in.topic, "/scan_" + std::to_string(i + 1));
    EXPECT_GE(in.integrated, 5u);
    EXPECT_GE(in.received, in.integrated);
    EXPECT_EQ(in.dropped_empty + in.dropped_bad_angles + in.dropped_bad_frame +
                  in.dropped_tf_too_old + in.dropped_no_valid_beam + in.dropped_bad_geometry +
                  in.dropped_out_of_extent + in.dropped_absurd_pose,
              0u);
    EXPECT_EQ(in.beam_count_mismatches, 0u);
    EXPECT_EQ(in.time_jumps, 0u);
    EXPECT_EQ(in.motion_fallbacks, 0u);
    EXPECT_GT(in.rate, 0.0);
    EXPECT_EQ(in.expected_rate, 10.0);
    integrated += in.integrated;
  }
  EXPECT_EQ(s->scans_integrated, integrated);
  EXPECT_GT(s->nodes, 0u);
  EXPECT_GT(s->bytes, 0u);
  EXPECT_GE(s->integrate_time_max, s->integrate_time_mean);
}

TEST(MappingSystem, MapUpdatesLieInsideTheFullGrid) {
  map_msgs::OccupancyGridUpdate::ConstPtr u;
  nav_msgs::OccupancyGrid::ConstPtr g;
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(20.0);
  while (ros::ok() && ros::WallTime::now() < end) {
    g_recorder->update(&u, &g);
    if (u && g) break;
    ros::WallDuration(0.05).sleep();
  }
  ASSERT_TRUE(u && g);
  EXPECT_EQ(u->header.frame_id, "map");
  EXPECT_GT(u->width, 0u);
  EXPECT_GT(u->height, 0u);
  EXPECT_EQ(u->data.size(), static_cast<std::size_t>(u->width) * u->height);
  EXPECT_GE(u->x, 0);
  EXPECT_GE(u->y, 0);
  EXPECT_LE(u->x + static_cast<int>(u->width), static_cast<int>(g->info.width));
  EXPECT_LE(u->y + static_cast<int>(u->height), static_cast<int>(g->info.height));
  // The scanners see the whole room, and the grid is the room: the update is at most the grid.
  EXPECT_LE(static_cast<std::size_t>(u->width) * u->height, g->data.size());
}

TEST(MappingSystem, DiagnosticsPerInputAndMapper) {
  // Early reports say "no scan received yet": wait until every input reports OK.
  const auto ready = [](const std::map<std::string, diagnostic_msgs::DiagnosticStatus>& d) {
    int ok = 0;
    for (const auto& kv : d) {
      if (kv.first.find(" input") != std::string::npos &&
          kv.second.level == diagnostic_msgs::DiagnosticStatus::OK) {
        ++ok;
      }
    }
    return ok == 4;
  };
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(20.0);
  std::map<std::string, diagnostic_msgs::DiagnosticStatus> d;
  while (ros::ok() && ros::WallTime::now() < end) {
    d = g_recorder->diagnostics();
    if (ready(d)) break;
    ros::WallDuration(0.05).sleep();
  }
  std::string names;
  for (const auto& kv : d) names += kv.first + "; ";
  for (int i = 1; i <= 4; ++i) {
    const std::string topic = "/scan_" + std::to_string(i);
    bool input = false, rate = false;
    for (const auto& kv : d) {
      if (kv.first.find(topic + " input") != std::string::npos) {
        input = true;
        EXPECT_EQ(kv.second.level, diagnostic_msgs::DiagnosticStatus::OK) << kv.second.message;
      }
      if (kv.first.find(topic + " rate") != std::string::npos) rate = true;
    }
    EXPECT_TRUE(input) << names;
    EXPECT_TRUE(rate) << names;
  }
  bool mapper = false;
  for (const auto& kv : d) mapper = mapper || kv.first.find("mapper") != std::string::npos;
  EXPECT_TRUE(mapper) << names;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_mapping_system");
  ros::NodeHandle nh;
  Recorder recorder;
  g_recorder = &recorder;

  tf2_ros::StaticTransformBroadcaster tf_broadcaster;
  tf_broadcaster.sendTransform(room::staticTree());

  std::vector<ros::Subscriber> subs;
  for (const std::string topic : {"map", "map_scale_2", "map_scale_3", "map_scale_4"}) {
    subs.push_back(nh.subscribe<nav_msgs::OccupancyGrid>(
        topic, 2,
        boost::function<void(const nav_msgs::OccupancyGrid::ConstPtr&)>(
            [topic](const nav_msgs::OccupancyGrid::ConstPtr& g) {
              g_recorder->onGrid(topic, g);
            })));
  }
  subs.push_back(room::keepLatest<nav_msgs::MapMetaData>(nh, "map_metadata", 2, &g_metadata_mutex,
                                                         &g_metadata));
  subs.push_back(nh.subscribe("wavog_mapping/status", 10, &Recorder::onStatus, &recorder));
  subs.push_back(nh.subscribe("map_updates", 10, &Recorder::onUpdate, &recorder));
  subs.push_back(nh.subscribe("/diagnostics", 10, &Recorder::onDiagnostics, &recorder));

  std::vector<ros::Publisher> pubs;
  for (int i = 1; i <= 4; ++i) {
    pubs.push_back(nh.advertise<sensor_msgs::LaserScan>("scan_" + std::to_string(i), 10));
  }
  std::atomic<bool> running{true};
  std::thread publisher([&] {
    ros::WallRate rate(10.0);
    while (running && ros::ok()) {
      const ros::Time stamp = ros::Time::now();
      for (std::size_t i = 0; i < pubs.size(); ++i) {
        pubs[i].publish(room::scanOf(room::sensors()[i], stamp));
      }
      rate.sleep();
    }
  });

  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  running = false;
  publisher.join();
  spinner.stop();
  return result;
}
