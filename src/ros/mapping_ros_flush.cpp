// The end of the input (a bag that ends, a robot whose drivers stop): scans still waiting in the
// tf filters for a transform that will never come are integrated with the latest one (counted as
// integrated_latest_tf), and the last partial publication period reaches the topics (~status at
// least, latched, so that it can be read after a bag's clock has stopped). Triggered by
// the idle timer (idle_timeout of wall time without any scan or tf), by ~flush and by ~save_map.
#include <ros/ros.h>
#include <tf2/exceptions.h>

#include <boost/make_shared.hpp>
#include <chrono>
#include <utility>

#include "fleet/fleet_stream.h"
#include "mapping_ros_impl.h"

namespace wavog_ros {
namespace {

std::int64_t steadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

void MappingRos::Impl::noteActivity() {
  last_activity_ns_.store(steadyNs());
  idle_handled_.store(false);
}

void MappingRos::Impl::onIdleTimer(const ros::WallTimerEvent&) {
  const double idle = static_cast<double>(steadyNs() - last_activity_ns_.load()) * 1e-9;
  if (idle < config_.ros.idle_timeout || idle_handled_.exchange(true)) return;
  const std::size_t n = flushPending();
  bool changed = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    changed = changed_since_publish_;
  }
  if (!changed) {
    publishStatus();  // the final counters (latched), after the last timer's publication
    return;
  }
  ROS_INFO(
      "%s: no scan or tf for %.1f s: %zu waiting scan(s) integrated with the latest tf, "
      "publishing the map",
      pnh_.getNamespace().c_str(), idle, n);
  publishAll();
}

std::size_t MappingRos::Impl::flushPending() {
  {
    std::lock_guard<std::mutex> tf_lock(tf_mutex_);
    for (auto& in : inputs_) in->filter->clear();
  }
  std::vector<std::pair<Input*, PendingScan>> waiting;
  std::size_t released = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto& in : inputs_) {
      // First those tf covers by now (the retry timer's work, done at once).
      released += releaseReadyLocked(in.get());
      for (auto& p : in->pending) waiting.emplace_back(in.get(), std::move(p));
      in->pending.clear();
      in->outside = 0;
    }
  }
  if (released > 0 && fleet_stream_) fleet_stream_->publishQueued();  // without the lock
  // No newer tf is coming: a scan tf covers is placed at its stamp, as wavog_offline places it
  // (motion-compensated if tf covers its sweep); one beyond the newest transform of its frame is
  // placed by that transform, uncompensated. The scans tf placed already, waiting for one received
  // before them, keep their placement; all in the order received.
  std::size_t flushed = 0;
  for (auto& w : waiting) {
    Input* in = w.first;
    if (w.second.placed) {
      std::lock_guard<std::mutex> lock(mutex_);
      integratePlacedScanLocked(in, *w.second.scan, w.second.placement);
      continue;
    }
    auto scan = boost::make_shared<sensor_msgs::LaserScan>(*w.second.scan);
    PlacementOptions options = placement_;
    std::string error;
    try {
      const auto t =
          buffer_->lookupTransform(placement_.fixed_frame, scan->header.frame_id, ros::Time(0));
      if (t.header.stamp < scan->header.stamp) {
        scan->header.stamp = t.header.stamp;
        options.motion_compensation = false;
      }
    } catch (const tf2::TransformException& e) {
      error = e.what();
    }
    const ScanPlacement placement =
        error.empty() ? placeScan(*buffer_, *scan, options) : ScanPlacement();
    std::lock_guard<std::mutex> lock(mutex_);
    if (!error.empty() || !placement.placed()) {
      dropLocked(in, DropReason::kTfUnavailable,
                 "input stopped, and tf never connected frame '" + scan->header.frame_id +
                     "' to '" + placement_.fixed_frame +
                     "': " + (error.empty() ? placement.error : error));
      continue;
    }
    const std::uint64_t before = in->c[Counter::kIntegrated];
    integrateLocked(in, *scan, placement);
    if (in->c[Counter::kIntegrated] > before) {
      ++in->c[Counter::kIntegratedLatestTf];
      in->c[Counter::kMotionFallbacks] += placement.motion_fallback ? 1 : 0;
      ++flushed;
    }
  }
  return flushed;
}

}  // namespace wavog_ros
