// A vehicle whose stream lags (test/fleet_lagging.test), the cause of fleet.test's failure on a
// loaded machine, made on purpose instead of by load: the test streams the placed scans of two
// simulated car-park vehicles at their real pace, v1's each at its stamp, v2's falling behind by
// 0.5 s a second up to 1 s (a mapper whose backlog grows), so that v2's scans reach the fleet
// node long after v1's scans of the same stamps have waited fleet_reorder_wait (0.3 s). v2 stops
// 1 s before v1 (killed); v3 is listed and never streams. Checks: nothing is late, lost or
// refused, the fleet map equals, cell for cell, one map fed every scan in stamp order; v3 holds
// nothing up (v1's last scans are integrated). By arrival time alone most of v2's scans came late
// and the maps differed.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <string>
#include <tuple>
#include <vector>

#include "fleet/placed_scan.h"
#include "map_compare.h"
#include "wavog_mapping/FleetStatus.h"
#include "wavog_mapping/PlacedScan.h"
#include "wavog_mapping/SaveMap.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/ros/config.h"
#include "wavog_mapping/sim/laser_sim.h"
#include "wavog_mapping/sim/world.h"

namespace {

constexpr double kDuration = 4.0;   ///< s of v1's drive; v2's ends 1 s earlier
constexpr double kMaxLag = 1.0;     ///< s v2's stream falls behind v1's
constexpr double kLagGrowth = 0.5;  ///< s of lag per s

/// One placed scan, and when the test sends it (s after the start).
struct Streamed {
  double send = 0.0;
  int vehicle = 0;  ///< 0: v1, 1: v2 (their places in fleet_vehicles)
  wavog_mapping::PlacedScan msg;
};

std::vector<Streamed> streams(const ros::Time& t0) {
  std::vector<Streamed> out;
  const wavog::sim::World base = wavog::sim::defaultWorld(kDuration);
  for (int k = 0; k < 2; ++k) {
    const wavog::sim::World w = wavog::sim::fleetMember(base, k, 2);
    wavog::sim::ScanSimulator sim(w, 21 + static_cast<std::uint64_t>(k));
    wavog::sim::SimScan s;
    std::uint64_t index = 0;
    while (sim.next(&s)) {
      if (k == 1 && s.stamp > kDuration - 1.0) break;
      const auto& laser = w.vehicle.lasers[static_cast<std::size_t>(s.laser)];
      wavog::ScanView view = s.view(laser);
      view.period = 1.0 / laser.rate_hz;
      Streamed p;
      p.vehicle = k;
      p.send = s.stamp + (k == 1 ? std::min(kMaxLag, kLagGrowth * s.stamp) : 0.0);
      wavog_fleet::fillPlacedScan(t0 + ros::Duration(s.stamp), "map", "v" + std::to_string(k + 1),
                                  laser.topic, index++, s.sensor_pose, view, false, s.sensor_pose,
                                  s.sensor_pose, &p.msg, nullptr);
      out.push_back(std::move(p));
    }
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const Streamed& a, const Streamed& b) { return a.send < b.send; });
  return out;
}

bool call(const std::string& service, std_srvs::Trigger* srv) {
  return ros::service::waitForService(service, ros::Duration(10.0)) &&
         ros::service::call(service, *srv) && srv->response.success;
}

TEST(FleetLagging, AVehicleThatStreamsBehindIsWaitedForNotLate) {
  ros::NodeHandle nh;
  std::mutex mutex;
  wavog_mapping::FleetStatus::ConstPtr status;
  ros::Subscriber sub = nh.subscribe<wavog_mapping::FleetStatus>(
      "/wavog_fleet/fleet_status", 10, [&](const wavog_mapping::FleetStatus::ConstPtr& s) {
        std::lock_guard<std::mutex> lock(mutex);
        status = s;
      });
  ros::AsyncSpinner spinner(1);
  spinner.start();
  std::vector<ros::Publisher> pubs = {
      nh.advertise<wavog_mapping::PlacedScan>("/v1/fleet_scans", 10000),
      nh.advertise<wavog_mapping::PlacedScan>("/v2/fleet_scans", 10000)};
  ASSERT_TRUE(ros::service::waitForService("/wavog_fleet/save_map", ros::Duration(30.0)));
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(20.0);
  for (const auto& pub : pubs) {
    while (pub.getNumSubscribers() == 0 && ros::WallTime::now() < give_up) {
      ros::WallDuration(0.05).sleep();
    }
    ASSERT_GT(pub.getNumSubscribers(), 0u) << pub.getTopic();
  }

  // At the pace of the stamps (the fleet node's clock is wall time here): each scan is sent at its
  // `send` time, never before; a late-running loop sends what is due at once, in order.
  const ros::Time t0 = ros::Time::now() + ros::Duration(0.5);
  const std::vector<Streamed> scans = streams(t0);
  std::vector<std::size_t> sent(2, 0);
  const ros::WallTime start = ros::WallTime::now() + ros::WallDuration(0.5);
  for (const Streamed& p : scans) {
    const ros::WallTime at = start + ros::WallDuration(p.send);
    if (ros::WallTime::now() < at) (at - ros::WallTime::now()).sleep();
    pubs[static_cast<std::size_t>(p.vehicle)].publish(p.msg);
    ++sent[static_cast<std::size_t>(p.vehicle)];
  }
  ASSERT_GT(sent[0], 500u);
  ASSERT_GT(sent[1], 300u);

  // Everything received and out of the reorder buffer (v2 and v1 silent for fleet_stale_timeout).
  const ros::WallTime settle_by = ros::WallTime::now() + ros::WallDuration(30.0);
  wavog_mapping::FleetStatus::ConstPtr last;
  for (;;) {
    ASSERT_LT(ros::WallTime::now(), settle_by) << "the fleet node kept scans buffered";
    ros::WallDuration(0.5).sleep();
    std_srvs::Trigger flush;
    ASSERT_TRUE(call("/wavog_fleet/flush", &flush));  // publishes ~fleet_status
    ros::WallDuration(0.2).sleep();
    std::lock_guard<std::mutex> lock(mutex);
    if (status && status->buffered == 0 && status->vehicles.size() == 3 &&
        status->vehicles[0].received == sent[0] && status->vehicles[1].received == sent[1]) {
      last = status;
      break;
    }
  }
  for (std::size_t k = 0; k < 2; ++k) {
    const wavog_mapping::VehicleStatus& v = last->vehicles[k];
    SCOPED_TRACE(v.vehicle);
    std::printf("fleet lagging test: %s received %llu, integrated %llu, late %llu, lost %llu\n",
                v.vehicle.c_str(), static_cast<unsigned long long>(v.received),
                static_cast<unsigned long long>(v.integrated),
                static_cast<unsigned long long>(v.integrated_late + v.dropped_late),
                static_cast<unsigned long long>(v.lost));
    EXPECT_EQ(v.integrated_late + v.dropped_late, 0u);
    EXPECT_EQ(v.integrated, sent[k]);
    EXPECT_EQ(v.lost + v.index_regressions + v.index_jumps + v.dropped_version + v.dropped_frame +
                  v.dropped_bad_stamp + v.dropped_bad_pose + v.dropped_bad_size +
                  v.dropped_refused + v.dropped_overflow,
              0u);
  }
  EXPECT_EQ(last->vehicles[2].received, 0u);
  EXPECT_TRUE(last->vehicles[2].stale);

  // The merge rule: one map fed every scan in stamp order (vehicle, index on ties).
  const std::string path = "/tmp/wavog_fleet_lagging_" + std::to_string(getpid()) + ".wmap";
  wavog_mapping::SaveMap save;
  save.request.path = path;
  ASSERT_TRUE(ros::service::call("/wavog_fleet/save_map", save) && save.response.success);
  const wavog_ros::Config config = wavog_ros::loadConfigFile(
      std::string(WAVOG_SOURCE_DIR) + "/test/ros/fleet_lagging.yaml", nullptr);
  std::vector<std::tuple<ros::Time, int, std::uint64_t, const wavog_mapping::PlacedScan*>> order;
  for (const Streamed& p : scans)
    order.emplace_back(p.msg.header.stamp, p.vehicle, p.msg.index, &p.msg);
  std::sort(order.begin(), order.end());
  wavog::WaveletMap single(config.map);
  std::vector<float> decoded;
  for (const auto& e : order) {
    const wavog_mapping::PlacedScan& m = *std::get<3>(e);
    ASSERT_EQ(
        single.integrate(wavog_fleet::placedPose(m), wavog_fleet::placedView(m, &decoded)).status,
        wavog::ScanStatus::kOk);
  }
  wavog::WaveletMap fleet(config.map);
  fleet.load(path);
  std::filesystem::remove(path);
  wavog::Raster rf, rs;
  ASSERT_TRUE(map_compare::finestRasters(fleet, single, &rf, &rs));
  const std::size_t differ = map_compare::differingCells(rf, rs);
  std::printf("fleet lagging test: %zu of %zu cells differ from the merge rule's map\n", differ,
              rf.log_odds.size());
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(map_compare::knownCells(rf), 50000u);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "fleet_lagging_test");
  return RUN_ALL_TESTS();
}
