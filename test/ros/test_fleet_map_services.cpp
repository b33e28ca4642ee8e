// The fleet node's map conventions (test/fleet_map_services.test, wavog_fleet as a node): after
// the placed scans the test streams for one vehicle, map_metadata carries `map`'s info with every
// publication, and dynamic_map (beside `map`) answers the same grid as `map`.
#include <gtest/gtest.h>
#include <nav_msgs/GetMap.h>
#include <nav_msgs/MapMetaData.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>

#include <cmath>
#include <cstdint>
#include <mutex>

#include "room.h"
#include "wavog_mapping/FleetStatus.h"
#include "wavog_mapping/PlacedScan.h"

namespace {

constexpr int kScans = 8;
constexpr int kBeams = 360;

std::mutex g_mutex;
nav_msgs::OccupancyGrid::ConstPtr g_map;
nav_msgs::MapMetaData::ConstPtr g_metadata;
wavog_mapping::FleetStatus::ConstPtr g_status;

/// Scan i of vehicle v1, standing at (0.1 i, 0) in a round room of radius 3 m, 10 Hz.
wavog_mapping::PlacedScan placedScan(int i, const ros::Time& t0) {
  wavog_mapping::PlacedScan m;
  m.version = wavog_mapping::PlacedScan::VERSION_FLOAT32;
  m.header.stamp = t0 + ros::Duration(0.1 * i);
  m.header.frame_id = "map";
  m.vehicle = "v1";
  m.input = "scan";
  m.index = static_cast<std::uint64_t>(i);
  m.x = m.start_x = m.end_x = 0.1 * i;
  m.angle_min = -M_PI;
  m.angle_increment = 2.0 * M_PI / kBeams;
  m.range_min = 0.05;
  m.range_max = 20.0;
  m.period = i == 0 ? 0.0 : 0.1;
  for (int j = 0; j < kBeams; ++j) {
    // Distance from (x, 0) along bearing a to the circle of radius 3 around the origin.
    const double a = m.angle_min + j * m.angle_increment;
    const double b = m.x * std::cos(a);
    m.ranges.push_back(static_cast<float>(-b + std::sqrt(b * b - m.x * m.x + 9.0)));
  }
  return m;
}

TEST(FleetMapServices, MapMetadataAndDynamicMapCarryTheFleetMap) {
  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<wavog_mapping::PlacedScan>("/v1/fleet_scans", 100, true);
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(30.0);
  while (pub.getNumSubscribers() == 0 && ros::WallTime::now() < give_up) {
    ros::WallDuration(0.05).sleep();
  }
  ASSERT_GT(pub.getNumSubscribers(), 0u) << "wavog_fleet never subscribed to /v1/fleet_scans";
  const ros::Time t0 = ros::Time::now();
  for (int i = 0; i < kScans; ++i) {
    pub.publish(placedScan(i, t0));
    ros::WallDuration(0.01).sleep();
  }
  const auto status = room::waitLatest(
      &g_mutex, &g_status,
      [](const wavog_mapping::FleetStatus& s) {
        return !s.vehicles.empty() && s.vehicles[0].integrated == kScans && s.buffered == 0;
      },
      30.0);
  ASSERT_TRUE(status && !status->vehicles.empty()) << "no ~fleet_status";
  ASSERT_EQ(status->vehicles[0].integrated, static_cast<std::uint64_t>(kScans));

  // A `map` published after the last scan, and its map_metadata (the latest of each soon agree).
  const ros::Time after = ros::Time::now();
  nav_msgs::MapMetaData::ConstPtr meta;
  nav_msgs::OccupancyGrid::ConstPtr map;
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(15.0);
  while (ros::WallTime::now() < end) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      meta = g_metadata;
      map = g_map;
    }
    if (map && meta && map->header.stamp > after &&
        meta->map_load_time == map->info.map_load_time) {
      break;
    }
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_TRUE(map && map->header.stamp > after) << "no map after the scans";
  ASSERT_TRUE(meta) << "nothing on map_metadata";
  EXPECT_EQ(meta->map_load_time, map->info.map_load_time);
  EXPECT_EQ(room::geometry(*meta), room::geometry(map->info));
  ASSERT_GT(map->info.width, 50u) << "the room (6 m wide at 0.1 m) is in the map";

  nav_msgs::GetMap srv;
  ASSERT_TRUE(ros::service::call("dynamic_map", srv));
  const nav_msgs::OccupancyGrid& served = srv.response.map;
  EXPECT_EQ(served.header.frame_id, "map");
  EXPECT_GE(served.header.stamp, map->header.stamp);
  EXPECT_EQ(room::geometry(served.info), room::geometry(map->info));
  EXPECT_TRUE(served.data == map->data) << "dynamic_map differs from map";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_fleet_map_services");
  ros::NodeHandle nh;
  auto map_sub = room::keepLatest<nav_msgs::OccupancyGrid>(nh, "map", 2, &g_mutex, &g_map);
  auto meta_sub =
      room::keepLatest<nav_msgs::MapMetaData>(nh, "map_metadata", 2, &g_mutex, &g_metadata);
  auto status_sub = room::keepLatest<wavog_mapping::FleetStatus>(nh, "wavog_fleet/fleet_status", 10,
                                                                 &g_mutex, &g_status);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  return RUN_ALL_TESTS();
}
