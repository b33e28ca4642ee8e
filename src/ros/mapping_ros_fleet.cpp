// MappingRos and the fleet (issue 30): the mapper's stream of placed scans (fleet_stream: true)
// and the fleet node's role (wavog_fleet: the vehicles' streams instead of LaserScans and tf; the
// same map, publication, status, diagnostics and services). The pieces live in src/ros/fleet/.
#include <ros/ros.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "fleet/fleet_receiver.h"
#include "fleet/fleet_stream.h"
#include "fleet/vehicle_windows.h"
#include "mapping_ros_impl.h"

namespace wavog_ros {

void MappingRos::Impl::startFleet(MapperRole role) {
  const RosParams& rp = config_.ros;
  if (role == MapperRole::kMapper) {
    if (!rp.fleet_vehicles.empty()) {
      ROS_WARN("%s: fleet_vehicles is read by wavog_fleet only; this mapper ignores it",
               pnh_.getNamespace().c_str());
    }
    if (!rp.fleet_region.empty()) {
      throw std::invalid_argument("fleet_region must be empty ([]) for a mapper: only wavog_fleet "
                                  "maps a region of the site");
    }
    if (!rp.fleet_stream) return;  // nothing advertised, nothing queued
    std::string vehicle = rp.vehicle_id;
    if (vehicle.empty()) vehicle = nh_.getNamespace();
    fleet_stream_ = std::make_unique<wavog_fleet::FleetStream>(
        nh_, vehicle, rp.map_frame, rp.fleet_stream_format == "uint16");
    ROS_INFO("%s: streaming integrated scans as vehicle '%s' on %s (ranges as %s)",
             pnh_.getNamespace().c_str(), vehicle.c_str(), fleet_stream_->topic().c_str(),
             rp.fleet_stream_format.c_str());
    return;
  }
  if (rp.fleet_stream) {
    throw std::invalid_argument("fleet_stream (true) must be false for wavog_fleet: the fleet "
                                "node integrates streams, it does not stream");
  }
  if (rp.publish_window > 0.0) {
    throw std::invalid_argument("publish_window (" + std::to_string(rp.publish_window) +
                                ") must be 0 for wavog_fleet: the fleet map has no robot to "
                                "centre a window on");
  }
  if (!rp.fleet_region.empty()) {
    ROS_INFO("%s: region shard: integrating into [%g, %g] x [%g, %g] m only (fleet_region)",
             pnh_.getNamespace().c_str(), rp.fleet_region[0], rp.fleet_region[2],
             rp.fleet_region[1], rp.fleet_region[3]);
  }
  // No tf input: an empty buffer keeps the shared paths (publication, flush) valid.
  buffer_ = std::make_unique<tf2_ros::Buffer>(ros::Duration(rp.tf_cache_time));
  fleet_ = std::make_unique<wavog_fleet::FleetReceiver>(
      nh_, pnh_, rp, config_.map.grid.resolution, &mutex_,
      [this](const wavog::Pose2& pose, const wavog::ScanView& view) {
        return integratePlacedLocked(pose, view);
      },
      updater_.get());
  if (rp.fleet_window > 0.0) {
    // A region shard's window holds its region's cells only: published in its private namespace
    // (~<vehicle>/fleet_map), so that the shards of a site never publish on one topic.
    ros::NodeHandle where = nh_;
    std::vector<std::string> names = rp.fleet_vehicles;
    if (!rp.fleet_region.empty()) {
      where = pnh_;
      for (std::string& n : names) n.erase(0, n.find_first_not_of('/'));
    }
    fleet_windows_ = std::make_unique<wavog_fleet::VehicleWindows>(where, names, rp.fleet_window);
  }
}

wavog::IntegrateStats MappingRos::Impl::integratePlacedLocked(const wavog::Pose2& pose,
                                                             const wavog::ScanView& view) {
  noteActivity();
  const auto t0 = std::chrono::steady_clock::now();
  const wavog::IntegrateStats st = map_.integrate(pose, view);
  const double dt =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  integrate_time_sum_ += dt;
  integrate_time_max_ = std::max(integrate_time_max_, dt);
  ++integrate_count_;
  if (st.status != wavog::ScanStatus::kOk) return st;
  changed_since_publish_ = true;
  const double res = map_.resolution();
  const MapBox box{static_cast<double>(st.touched.min_x) * res,
                   static_cast<double>(st.touched.min_y) * res,
                   static_cast<double>(st.touched.max_x) * res,
                   static_cast<double>(st.touched.max_y) * res};
  publisher_->touched(box);
  publisher_->sensorAt(pose.x, pose.y);
  if (fleet_windows_) fleet_windows_->touched(box);
  return st;
}

}  // namespace wavog_ros
