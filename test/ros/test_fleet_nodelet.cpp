// The fleet map run as a nodelet (test/fleet_nodelet.test): the test streams placed scans as a
// vehicle's mapper would (PlacedScan on /v1/fleet_scans); the nodelet integrates every one,
// ~fleet_status counts them, and the map it saves equals, cell for cell, the map the core makes
// of the same scans under the same parameters.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <cmath>
#include <mutex>
#include <string>
#include <vector>

#include "wavog_mapping/FleetStatus.h"
#include "wavog_mapping/PlacedScan.h"
#include "wavog_mapping/SaveMap.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/ros/config.h"

namespace {

constexpr int kScans = 12;
constexpr int kBeams = 181;

/// Scan i of a laser driving along x at 1 m/s past a wall 3 m to its left, 40 Hz.
wavog_mapping::PlacedScan placedScan(int i, const ros::Time& t0) {
  wavog_mapping::PlacedScan m;
  m.version = wavog_mapping::PlacedScan::FORMAT_VERSION;
  m.header.stamp = t0 + ros::Duration(0.025 * i);
  m.header.frame_id = "map";
  m.vehicle = "v1";
  m.input = "scan";
  m.index = static_cast<std::uint64_t>(i);
  m.x = m.start_x = m.end_x = 0.025 * i;
  m.y = m.start_y = m.end_y = 0.0;
  m.theta = m.start_theta = m.end_theta = 0.0;
  m.angle_min = 0.0;
  m.angle_increment = M_PI / (kBeams - 1);
  m.range_min = 0.05;
  m.range_max = 20.0;
  m.period = i == 0 ? 0.0 : 0.025;
  for (int j = 0; j < kBeams; ++j) {
    const double a = m.angle_min + j * m.angle_increment;
    const double s = std::sin(a);
    m.ranges.push_back(static_cast<float>(s > 0.2 ? 3.0 / s : 15.0));  // the wall y = 3
  }
  return m;
}

TEST(FleetNodelet, IntegratesPlacedScansAsTheCoreDoes) {
  ros::NodeHandle nh;
  std::mutex mutex;
  wavog_mapping::FleetStatus::ConstPtr status;
  ros::Subscriber sub = nh.subscribe<wavog_mapping::FleetStatus>(
      "/wavog_fleet/fleet_status", 10, [&](const wavog_mapping::FleetStatus::ConstPtr& s) {
        std::lock_guard<std::mutex> lock(mutex);
        status = s;
      });
  ros::Publisher pub = nh.advertise<wavog_mapping::PlacedScan>("/v1/fleet_scans", 100, true);
  ASSERT_TRUE(ros::service::waitForService("/wavog_fleet/save_map", ros::Duration(30.0)));
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(20.0);
  while (pub.getNumSubscribers() == 0 && ros::WallTime::now() < give_up) {
    ros::WallDuration(0.05).sleep();
  }
  ASSERT_GT(pub.getNumSubscribers(), 0u) << "the fleet nodelet never subscribed to /v1/fleet_scans";

  const wavog_ros::Config config = wavog_ros::loadConfigFile(
      std::string(WAVOG_SOURCE_DIR) + "/test/ros/fleet_nodelet.yaml", nullptr);
  wavog::WaveletMap expected(config.map);
  const ros::Time t0 = ros::Time::now();
  for (int i = 0; i < kScans; ++i) {
    const wavog_mapping::PlacedScan m = placedScan(i, t0);
    pub.publish(m);
    wavog::ScanView view{m.ranges.data(), m.ranges.size(), m.angle_min, m.angle_increment,
                         m.range_min, m.range_max};
    view.period = m.period;
    ASSERT_EQ(expected.integrate({m.x, m.y, m.theta}, view).status, wavog::ScanStatus::kOk);
    ros::WallDuration(0.01).sleep();
  }

  // Every scan integrated (the reorder wait is 0.2 s), as ~fleet_status says.
  std::uint64_t integrated = 0;
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(30.0);
  while (ros::WallTime::now() < deadline) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (status && status->vehicles.size() == 1) integrated = status->vehicles[0].integrated;
    }
    if (integrated == kScans) break;
    ros::WallDuration(0.1).sleep();
  }
  ASSERT_EQ(integrated, static_cast<std::uint64_t>(kScans));
  {
    std::lock_guard<std::mutex> lock(mutex);
    EXPECT_EQ(status->vehicles[0].vehicle, "v1");
    EXPECT_EQ(status->vehicles[0].lost, 0u);
    EXPECT_EQ(status->vehicles[0].dropped_refused, 0u);
  }

  const std::string path = ::testing::TempDir() + "wavog_fleet_nodelet.wmap";
  wavog_mapping::SaveMap srv;
  srv.request.path = path;
  ASSERT_TRUE(ros::service::call("/wavog_fleet/save_map", srv));
  ASSERT_TRUE(srv.response.success) << srv.response.message;
  wavog::WaveletMap saved(config.map);
  saved.load(path);
  wavog::CellBox box;
  ASSERT_TRUE(expected.bounds(0, &box));
  std::size_t occupied = 0;
  for (std::int64_t y = box.min_y; y < box.max_y; ++y) {
    for (std::int64_t x = box.min_x; x < box.max_x; ++x) {
      ASSERT_EQ(saved.value({x, y}), expected.value({x, y})) << "cell " << x << ", " << y;
      ASSERT_EQ(saved.isObserved({x, y}), expected.isObserved({x, y})) << "cell " << x << ", " << y;
      occupied += expected.value({x, y}) > 0.0f ? 1 : 0;
    }
  }
  EXPECT_GT(occupied, 20u) << "the wall is in the map";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_fleet_nodelet");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}
