// Scans waiting for tf, between the tf filter and the map: an input's scans leave in->pending in
// the order received (releaseReadyLocked), each once tf covers its stamp + tf_tolerance and, with
// motion compensation, its sweep's end. A scan the full filter pushed out, or one that passed it
// before tf reached its sweep's end, waits here (`outside`), retried by a wall timer; the drop
// rules bound the wait (outsideDropLocked). Called from mapping_ros_scans.cpp (onTransformable,
// onFilterFailure) and mapping_ros_flush.cpp.
#include <ros/ros.h>
#include <tf2/exceptions.h>

#include <algorithm>
#include <sstream>

#include "fleet/fleet_stream.h"
#include "mapping_ros_impl.h"

namespace wavog_ros {

PendingScan* MappingRos::Impl::findPendingLocked(Input* in, const sensor_msgs::LaserScan* scan) {
  auto& p = in->pending;
  const auto it = std::find_if(p.begin(), p.end(),
                               [scan](const PendingScan& s) { return s.scan.get() == scan; });
  return it == p.end() ? nullptr : &*it;
}

std::size_t MappingRos::Impl::releaseReadyLocked(Input* in) {
  auto& p = in->pending;
  std::size_t n = 0;
  const ros::Duration tolerance(config_.ros.tf_tolerance);
  const auto covered = [&](const PendingScan& s) {
    const std_msgs::Header& h = s.scan->header;
    return buffer_->canTransform(placement_.fixed_frame, h.frame_id, h.stamp) &&
           buffer_->canTransform(placement_.fixed_frame, h.frame_id, h.stamp + tolerance);
  };
  // ... and the sweep's end, when its motion is compensated.
  const auto transformable = [&](const PendingScan& s) {
    ros::Time end;
    return covered(s) &&
           (!sweepEndStamp(*s.scan, placement_, &end) ||
            buffer_->canTransform(placement_.fixed_frame, s.scan->header.frame_id, end));
  };
  // A scan tf cannot place while more than queue_size scans behind it are placed (tf for its
  // frame alone missing; the filter, holding only it, never overflows) no longer holds them up.
  // One that tf can place is on its way here (a spinner thread between the filter and
  // onTransformable), however long its thread is descheduled: it is waited for. The scans pushed
  // out of the filter are not counted: they wait here for tf, not for a thread.
  const std::size_t limit = 2 * static_cast<std::size_t>(config_.ros.queue_size);
  while (!p.empty()) {
    PendingScan& front = p.front();
    if (front.placed) {
      const PendingScan next = std::move(front);
      p.pop_front();
      ++n;
      integratePlacedScanLocked(in, *next.scan, next.placement);
      continue;
    }
    if (front.outside) {
      // Placed here as the filter would have placed it (tf covers its stamp + tf_tolerance and
      // the sweep's end), or at a bound with only the sweep's end missing (uncompensated).
      DropReason reason{};
      std::string why;
      if (transformable(front) ||
          (!(why = outsideDropLocked(in, &reason)).empty() && covered(front))) {
        front.placement = placeScan(*buffer_, *front.scan, placement_);
        front.placed = true;
        front.outside = false;
        --in->outside;
        continue;
      }
      if (why.empty()) break;
      p.pop_front();
      --in->outside;
      ++n;
      dropLocked(in, reason, why);
      continue;
    }
    const std_msgs::Header& h = front.scan->header;
    const bool tolerance_covered =
        buffer_->canTransform(placement_.fixed_frame, h.frame_id, h.stamp + tolerance);
    if (p.size() - in->outside > limit && !tolerance_covered) {
      p.pop_front();
      ++n;
      dropLocked(in, DropReason::kTfUnavailable, laterScansPlacedText());
      continue;
    }
    // tf covers its stamp + tf_tolerance but not its stamp: the stamp lies before the oldest
    // transform of its frame (a scan stamped just before the first tf), which tf never covers.
    // The filter keeps such a scan until newer ones push it out, and those pass straight through:
    // it held up its input until the end (wavog_offline drops it as tf_extrapolation).
    if (tolerance_covered && !buffer_->canTransform(placement_.fixed_frame, h.frame_id, h.stamp)) {
      p.pop_front();
      ++n;
      dropLocked(in, DropReason::kTfTooOld,
                 "stamp before the oldest transform of its frame (tf covers it from less than "
                 "tf_tolerance later on)");
      continue;
    }
    break;
  }
  return n;
}

std::string MappingRos::Impl::laterScansPlacedText() const {
  return "no transform to '" + placement_.fixed_frame + "' while " +
         std::to_string(config_.ros.queue_size) + " (queue_size) later scans were placed";
}

std::string MappingRos::Impl::outsideDropLocked(Input* in, DropReason* reason) {
  const auto& p = in->pending;
  const sensor_msgs::LaserScan& scan = *p.front().scan;
  const std::string& frame = scan.header.frame_id;
  const std::string& fixed = placement_.fixed_frame;
  const int queue_size = config_.ros.queue_size;
  *reason = DropReason::kTfUnavailable;
  const bool connected = buffer_->canTransform(fixed, frame, ros::Time(0));
  ros::Time newest;  // of the transforms between the frames (zero: static ones only)
  if (connected) {
    try {
      newest = buffer_->lookupTransform(fixed, frame, ros::Time(0)).header.stamp;
    } catch (const tf2::TransformException&) {
      // tf cleared meanwhile (a clock jump): nothing newer to compare with.
    }
  }
  // As for the scans in the filter (releaseReadyLocked): tf for its frame alone missing.
  const auto placed =
      std::count_if(p.begin(), p.end(), [](const PendingScan& s) { return s.placed; });
  if (placed > queue_size) {
    if (!connected) return noTransformText(*buffer_, frame, fixed, queue_size);
    return laterScansPlacedText();
  }
  // tf can no longer place it: the newest transform between the frames is more than the buffer's
  // length (tf_cache_time) after the scan, so the one at its stamp is gone or never comes.
  if (connected && newest > scan.header.stamp &&
      (newest - scan.header.stamp).toSec() > config_.ros.tf_cache_time) {
    *reason = DropReason::kTfTooOld;
    std::ostringstream text;
    text << "stamp older than the tf buffer (tf_cache_time " << config_.ros.tf_cache_time
         << " s) before tf covered it: it waited for tf with more than queue_size " << queue_size
         << " scans";
    return text.str();
  }
  // The memory bound: as many scans waiting for tf as roscpp may hold for the input.
  const auto bound = static_cast<std::size_t>(config_.ros.subscriber_queue_size);
  if (in->outside <= bound) return "";
  if (!connected) return noTransformText(*buffer_, frame, fixed, queue_size);
  return "no transform from '" + frame + "' to '" + fixed +
         "' at the scan's stamp while more than " + std::to_string(bound) +
         " (subscriber_queue_size) scans beyond the tf filter's " + std::to_string(queue_size) +
         " (queue_size) waited for tf: tf is that late, or stopped";
}

void MappingRos::Impl::onRetryTimer(const ros::WallTimerEvent&) {
  std::size_t released = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto& in : inputs_) {
      if (in->outside > 0) released += releaseReadyLocked(in.get());
    }
  }
  if (released > 0 && fleet_stream_) fleet_stream_->publishQueued();  // without the lock
}

}  // namespace wavog_ros
