// The fleet map run as a nodelet (test/fleet_nodelet.test): the test streams placed scans as a
// vehicle's mapper would (PlacedScan on /v1/fleet_scans); the nodelet integrates every one,
// ~fleet_status counts them, and the map it saves equals, cell for cell, the map the core makes
// of the same scans under the same parameters. Then hostile messages on /v2/fleet_scans (stamps
// at and beyond 2^31 s from now, nsec overflow, a far-future stamp, a NaN pose part): the nodelet
// keeps running, refuses each under its reason, and counts none of them as lost.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <cmath>
#include <limits>
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
  m.version = wavog_mapping::PlacedScan::VERSION_FLOAT32;
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
      if (status && !status->vehicles.empty()) integrated = status->vehicles[0].integrated;
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

/// The latest ~fleet_status, kept by a subscription.
struct StatusListener {
  std::mutex mutex;
  wavog_mapping::FleetStatus::ConstPtr status;
  ros::Subscriber sub;
  explicit StatusListener(ros::NodeHandle& nh) {
    sub = nh.subscribe<wavog_mapping::FleetStatus>(
        "/wavog_fleet/fleet_status", 10, [this](const wavog_mapping::FleetStatus::ConstPtr& s) {
          std::lock_guard<std::mutex> lock(mutex);
          status = s;
        });
  }
  wavog_mapping::FleetStatus::ConstPtr latest() {
    std::lock_guard<std::mutex> lock(mutex);
    return status;
  }
};

TEST(FleetNodelet, HostileStampsAndPosesAreRefusedAndTheNodeletLives) {
  ros::NodeHandle nh;
  StatusListener listener(nh);
  ros::Publisher pub = nh.advertise<wavog_mapping::PlacedScan>("/v2/fleet_scans", 100);
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(20.0);
  while (pub.getNumSubscribers() == 0 && ros::WallTime::now() < give_up) {
    ros::WallDuration(0.05).sleep();
  }
  ASSERT_GT(pub.getNumSubscribers(), 0u) << "the fleet nodelet never subscribed to /v2/fleet_scans";
  ros::WallDuration(0.5).sleep();  // the connection's other side

  const ros::Time t0 = ros::Time::now();
  std::vector<wavog_mapping::PlacedScan> msgs;
  for (int i = 0; i < 8; ++i) {
    msgs.push_back(placedScan(i, t0));
    msgs.back().vehicle = "v2";
  }
  msgs[1].header.stamp.sec = 4294967295u;  // 2^32 - 1 s: more than 2^31 s from now
  msgs[2].header.stamp.nsec = 0xFFFFFFFFu;  // not normalised
  msgs[3].header.stamp.sec = 4294967295u;
  msgs[3].header.stamp.nsec = 0xFFFFFFFFu;
  msgs[4].header.stamp = t0 + ros::Duration(1e6);  // within ROS time, 11 days ahead
  msgs[5].start_theta = std::numeric_limits<double>::quiet_NaN();
  msgs[6].theta = msgs[6].end_theta = 1e30;
  for (const auto& m : msgs) {
    pub.publish(m);
    ros::WallDuration(0.02).sleep();
  }
  const std::uint64_t sent = msgs.size();
  wavog_mapping::FleetStatus::ConstPtr s;
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(30.0);
  while (ros::WallTime::now() < deadline) {
    s = listener.latest();
    if (s && s->vehicles.size() == 2 && s->vehicles[1].received == sent &&
        s->vehicles[1].integrated == 2 && s->buffered == 0) {
      break;
    }
    ros::WallDuration(0.1).sleep();
  }
  ASSERT_TRUE(s && s->vehicles.size() == 2) << "no ~fleet_status from the nodelet";
  const wavog_mapping::VehicleStatus& v = s->vehicles[1];
  EXPECT_EQ(v.vehicle, "v2");
  EXPECT_EQ(v.received, sent);
  EXPECT_EQ(v.integrated, 2u);  // scans 0 and 7
  EXPECT_EQ(v.dropped_bad_stamp, 4u);
  EXPECT_EQ(v.dropped_bad_pose, 2u);
  EXPECT_EQ(v.lost, 0u) << "refused messages were delivered";
  EXPECT_EQ(v.index_regressions + v.index_jumps, 0u);
  // Alive: it still answers and publishes its status after the hostile messages.
  const ros::Time stamp = s->header.stamp;
  const ros::WallTime later = ros::WallTime::now() + ros::WallDuration(10.0);
  while (ros::WallTime::now() < later && listener.latest()->header.stamp == stamp) {
    ros::WallDuration(0.1).sleep();
  }
  EXPECT_GT(listener.latest()->header.stamp, stamp) << "the nodelet stopped publishing";
  EXPECT_TRUE(ros::service::exists("/wavog_fleet/save_map", false));
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_fleet_nodelet");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}
