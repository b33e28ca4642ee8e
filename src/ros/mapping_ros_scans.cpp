// One scan through MappingRos, in the order it travels: onScan (counted, checked, time jumps) ->
// the input's tf MessageFilter (fed by onTf; failures in onFilterFailure) -> onTransformable
// (placeScan: tf at the first and last beam) -> releaseReadyLocked (mapping_ros_tf_wait.cpp: in the
// order received) -> integrateLocked (the core call, the counters and the dirty region of
// map_updates).
#include <ros/ros.h>
#include <tf2/exceptions.h>

#include <algorithm>
#include <boost/make_shared.hpp>
#include <chrono>
#include <sstream>

#include "fleet/fleet_stream.h"
#include "mapping_ros_impl.h"
#include "wavog_mapping/ros/conversions.h"

namespace wavog_ros {
namespace {

using Clock = std::chrono::steady_clock;

/// Stamps (or the clock) going back by more than this (s) are a time jump (e.g. a bag restart).
constexpr double kTimeJumpThreshold = 1.0;
/// Why the core refused a scan, as a drop reason.
DropReason refusal(wavog::ScanStatus status) {
  switch (status) {
    case wavog::ScanStatus::kEmpty:
      return DropReason::kEmpty;
    case wavog::ScanStatus::kNoValidBeam:
      return DropReason::kNoValidBeam;
    case wavog::ScanStatus::kOutOfExtent:
      return DropReason::kOutOfExtent;
    case wavog::ScanStatus::kBadPose:
      return DropReason::kAbsurdPose;
    default:
      return DropReason::kBadGeometry;
  }
}

}  // namespace

void MappingRos::Impl::onScan(Input* in, const sensor_msgs::LaserScan::ConstPtr& received,
                              std::uintptr_t connection) {
  if (in->freq) in->freq->tick();  // FrequencyStatus locks itself
  noteActivity();
  const ros::Time now = ros::Time::now();
  // tf1-era frame ids ("/laser"): tf2 refuses them, so the scan goes on with the slash removed.
  sensor_msgs::LaserScan::ConstPtr scan = received;
  bool stripped = false;
  if (!received->header.frame_id.empty() && received->header.frame_id[0] == '/') {
    auto copy = boost::make_shared<sensor_msgs::LaserScan>(*received);
    stripped = stripFrameSlash(&copy->header.frame_id);
    scan = copy;
  }
  bool clear_tf = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stripped && !in->slash_warned) {
      in->slash_warned = true;
      ROS_WARN("%s: %s", in->topic.c_str(), frameSlashWarning(received->header.frame_id).c_str());
    }
    InputCounters& c = in->c;
    ++c[Counter::kReceived];
    ++c.received_in_period;
    countLostLocked(in, *received, connection);
    c.last_receipt = now;
    // The clock jumping backwards (a bag restarted with --clock): the tf buffer holds the old
    // future and would refuse every new scan, so clear it and go on.
    if (!last_now_.isZero() && secondsBetween(last_now_, now) > kTimeJumpThreshold) {
      ++clock_jumps_;
      clear_tf = true;
    }
    last_now_ = now;
    // Stamps jumping backwards on one input (a bag restarted without --clock, a driver reset):
    // counted and warned; such a scan is placed by tf if its stamp is still in the buffer, else
    // dropped as too old.
    const double back = secondsBetween(c.last_received_stamp, scan->header.stamp);
    if (!c.last_received_stamp.isZero() && back > kTimeJumpThreshold) {
      ++c[Counter::kTimeJumps];
      warnLocked(in, kOtherWarning, "stamp jumped backwards by " + std::to_string(back) + " s");
    }
    c.last_received_stamp = scan->header.stamp;
    DropReason reason{};
    const bool checked = checkScan(*scan, &reason);
    if (checked) countOddGeometryLocked(in, *scan);
    if (!checked) {
      std::ostringstream detail;
      detail << "frame_id '" << scan->header.frame_id << "', " << scan->ranges.size()
             << " ranges, angles [" << scan->angle_min << ", " << scan->angle_max << "] step "
             << scan->angle_increment;
      dropLocked(in, reason, detail.str());
      return;
    }
    // Before the tf filter, which adds tf_tolerance to the stamp (and would throw).
    if (!checkScanTime(*scan, config_.ros.tf_tolerance, &reason)) {
      std::ostringstream detail;
      detail << "stamp " << scan->header.stamp.sec << "." << scan->header.stamp.nsec
             << " s, time_increment " << scan->time_increment << " s over "
             << scan->ranges.size() << " beams (sweep at most " << kMaxSweepSeconds
             << " s, stamps within ROS time)";
      dropLocked(in, reason, detail.str());
      return;
    }
    // Before the filter may hand it on.
    in->pending.push_back(PendingScan{scan, false, ScanPlacement()});
  }
  std::lock_guard<std::mutex> tf_lock(tf_mutex_);
  if (clear_tf) {
    ROS_WARN("%s: clock jumped backwards: tf buffer cleared", pnh_.getNamespace().c_str());
    buffer_->clear();
  }
  in->filter->add(scan);
}

void MappingRos::Impl::onRefusedScan(Input* in, const sensor_msgs::LaserScan& partial,
                                     const Refused& refused) {
  if (in->freq) in->freq->tick();
  noteActivity();
  std::lock_guard<std::mutex> lock(mutex_);
  ++in->c[Counter::kReceived];
  ++in->c.received_in_period;
  in->c.last_receipt = ros::Time::now();
  // header.seq is the message's first field: read unless the message is shorter than 4 bytes.
  if (refused.bytes_read >= sizeof(partial.header.seq)) {
    countLostLocked(in, partial, refused.connection);
  }
  dropLocked(in, DropReason::kBadLength,
             "a message of " + std::to_string(refused.length) +
                 " bytes refused before deserialisation: " + refused.why);
}

void MappingRos::Impl::countLostLocked(Input* in, const sensor_msgs::LaserScan& scan,
                                       std::uintptr_t connection) {
  const std::uint32_t lost = in->c.seq.next(scan.header.seq, connection);
  if (lost == 0) return;
  const std::uint64_t total = in->c[Counter::kLost] += lost;
  warnLocked(in, kLostWarning,
             std::to_string(lost) + " scan(s) lost before the node received them (header.seq " +
                 std::to_string(scan.header.seq - lost - 1) + " -> " +
                 std::to_string(scan.header.seq) + ", " + std::to_string(total) +
                 " lost so far), most likely dropped by a full subscriber queue "
                 "(subscriber_queue_size " +
                 std::to_string(config_.ros.subscriber_queue_size) +
                 "): the node is slower than this input. Raise subscriber_queue_size, play the "
                 "bag slower (rosbag play -r), or give the node more CPU (a less loaded host, "
                 "fewer publish_scales, a coarser resolution, num_threads)");
}

void MappingRos::Impl::countOddGeometryLocked(Input* in, const sensor_msgs::LaserScan& scan) {
  if (beamCountMismatch(scan)) {
    const std::uint64_t n = ++in->c[Counter::kBeamCountMismatches];
    std::ostringstream text;
    text << scan.ranges.size() << " ranges, but angle_min " << scan.angle_min << ", angle_max "
         << scan.angle_max << " and angle_increment " << scan.angle_increment << " imply "
         << impliedBeams(scan) << " beams (" << n
         << " such scans so far): integrated as laser_geometry places them, beam i at angle_min "
            "+ i * angle_increment (angle_max unused)";
    warnLocked(in, kBeamCountWarning, text.str());
  }
  if (intensitiesMismatch(scan)) {
    const std::uint64_t n = ++in->c[Counter::kIntensitiesIgnored];
    warnLocked(in, kIntensitiesWarning,
               std::to_string(scan.intensities.size()) + " intensities for " +
                   std::to_string(scan.ranges.size()) + " ranges (" + std::to_string(n) +
                   " such scans so far): intensities ignored, the scan is integrated");
  }
}

void MappingRos::Impl::onTf(const tf2_msgs::TFMessage::ConstPtr& msg, bool is_static) {
  noteActivity();
  std::uint64_t refused = 0;
  {
    std::lock_guard<std::mutex> tf_lock(tf_mutex_);
    for (const auto& t : msg->transforms) {
      // The buffer's pruning adds its cache length to the stamp and would throw.
      if (!tfStampUsable(t.header.stamp, config_.ros.tf_cache_time)) {
        ++refused;
        ROS_WARN_THROTTLE(kWarnPeriod, "%s: transform %s -> %s refused: stamp %u.%09u s is too late for ROS time",
                          pnh_.getNamespace().c_str(), t.header.frame_id.c_str(),
                          t.child_frame_id.c_str(), t.header.stamp.sec, t.header.stamp.nsec);
        continue;
      }
      try {
        // false: refused (NaN, empty or equal frame ids...; tf2 logs why).
        if (!buffer_->setTransform(t, "default_authority", is_static)) ++refused;
      } catch (const tf2::TransformException& e) {
        ++refused;
        ROS_WARN_THROTTLE(kWarnPeriod, "%s: transform refused by the tf buffer: %s",
                          pnh_.getNamespace().c_str(), e.what());
      }
    }
  }
  if (refused > 0) {
    std::lock_guard<std::mutex> lock(mutex_);
    tf_refused_ += refused;
  }
}

void MappingRos::Impl::onFilterFailure(
    Input* in, const sensor_msgs::LaserScan::ConstPtr& scan,
    tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto& pending = in->pending;
  const auto it = std::find_if(pending.begin(), pending.end(),
                               [&scan](const PendingScan& p) { return p.scan == scan; });
  if (it == pending.end()) return;  // already flushed
  // Pushed out of the full filter (more than queue_size scans waiting: tf late, e.g. a loaded
  // host, or not yet there at start-up): it waits in its turn, placed once tf covers it
  // (releaseReadyLocked), so that how late tf comes does not change the map. A frame tf does not
  // connect (yet) is named at once; its scans are dropped when later ones are placed, or at the
  // memory bound (outsideDropLocked).
  if (reason == tf2_ros::filter_failure_reasons::Unknown) {
    if (!it->outside) {
      it->outside = true;
      ++in->outside;
    }
    if (!buffer_->canTransform(placement_.fixed_frame, scan->header.frame_id, ros::Time(0))) {
      warnLocked(in, kOtherWarning,
                 "more than queue_size " + std::to_string(config_.ros.queue_size) +
                     " scans waiting for tf, and " +
                     noTransformText(*buffer_, scan->header.frame_id, placement_.fixed_frame,
                                     config_.ros.queue_size) +
                     " (the scans wait for tf up to subscriber_queue_size " +
                     std::to_string(config_.ros.subscriber_queue_size) + ")");
    }
    releaseReadyLocked(in);
    return;
  }
  // Dropped now, not in its turn: a drop changes no map, so its order does not matter.
  if (it->outside) --in->outside;
  pending.erase(it);
  if (reason == tf2_ros::filter_failure_reasons::OutTheBack) {
    dropLocked(in, DropReason::kTfTooOld, "stamp older than the tf buffer");
  } else if (reason == tf2_ros::filter_failure_reasons::EmptyFrameID) {
    dropLocked(in, DropReason::kBadFrame, "empty frame_id");
  } else {
    // Unknown: tf never came in time, or the filter's queue overflowed (it drops its oldest scan
    // when more than queue_size wait for tf).
    dropLocked(in, DropReason::kTfUnavailable,
               noTransformText(*buffer_, scan->header.frame_id, placement_.fixed_frame,
                               config_.ros.queue_size));
  }
  releaseReadyLocked(in);  // the scans this one held up
}

void MappingRos::Impl::onTransformable(Input* in, const sensor_msgs::LaserScan::ConstPtr& scan) {
  // tf lookups outside the lock: the buffer locks itself. The filter calls this from any of the
  // spinner's threads, several scans at once when tf comes late and in bursts (a loaded host):
  // the placement is kept, and the scan waits in in->pending for those received before it.
  const ScanPlacement placement = placeScan(*buffer_, *scan, placement_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    PendingScan* p = findPendingLocked(in, scan.get());
    if (p == nullptr) return;  // flushed meanwhile (flushPending)
    if (placement.end_missing) {
      // tf reached the stamp + tf_tolerance, not yet the sweep's end: whether it had would
      // depend on how busy the host is, so the scan waits here for it as the scans pushed out
      // of the filter do (releaseReadyLocked, the retry timer, flushPending).
      p->outside = true;
      ++in->outside;
    } else {
      p->placed = true;
      p->placement = placement;
    }
    releaseReadyLocked(in);
  }
  if (fleet_stream_) fleet_stream_->publishQueued();  // without the lock
}

void MappingRos::Impl::integratePlacedScanLocked(Input* in, const sensor_msgs::LaserScan& scan,
                                                 const ScanPlacement& placement) {
  if (!placement.placed()) {
    dropLocked(in, DropReason::kTfUnavailable, placement.error);
    return;
  }
  if (placement.motion_fallback) {
    ++in->c[Counter::kMotionFallbacks];
    warnLocked(in, kOtherWarning, motionFallbackText(config_.ros.queue_size, sweepSeconds(scan)));
  }
  integrateLocked(in, scan, placement);
}

void MappingRos::Impl::integrateLocked(Input* in, const sensor_msgs::LaserScan& scan,
                                       const ScanPlacement& placement) {
  // tf can place a laser anywhere (corrupt odometry): refused before the core sees it.
  const double first_beam = scan.header.stamp.toSec();
  const double last_beam = first_beam + (placement.compensate ? sweepSeconds(scan) : 0.0);
  const std::string absurd = in->poses.check(scan.header.frame_id, placement.start, first_beam,
                                             placement.end, last_beam);
  if (!absurd.empty()) {
    dropLocked(in, DropReason::kAbsurdPose, absurd);
    return;
  }
  wavog::Pose2 pose;
  wavog::ScanView view = placement.placedView(scan, &compensator_, &pose);
  view.period = in->period.next(scan.header.stamp.toSec(), scan.scan_time);
  // Streaming 16-bit codes: the map takes the decoded ranges, as the fleet will.
  if (fleet_stream_) view = fleet_stream_->streamView(view, map_.params());
  const auto t0 = Clock::now();
  const wavog::IntegrateStats st = map_.integrate(pose, view);
  const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
  integrate_time_sum_ += dt;
  integrate_time_max_ = std::max(integrate_time_max_, dt);
  ++integrate_count_;
  InputCounters& c = in->c;
  c[Counter::kBeamsHit] += st.beams_hit;
  c[Counter::kBeamsInvalid] += st.beams_invalid;
  c[Counter::kBeamsNoReturn] += st.beams_no_return;
  c[Counter::kBeamsBeyondLimit] += st.beams_beyond_limit;
  c[Counter::kNodesVisited] += st.nodes_visited;
  c[Counter::kBlocksTouched] += st.blocks_touched;
  if (st.status != wavog::ScanStatus::kOk) {
    dropLocked(in, refusal(st.status), coreRefusal(st, view, pose, map_.params()));
    return;
  }
  ++c[Counter::kIntegrated];
  if (fleet_stream_) {  // the very pose and view the core took
    fleet_stream_->queue(scan.header.stamp, in->topic, pose, view, placement.compensate,
                         placement.start, placement.end);
  }
  changed_since_publish_ = true;
  c.last_stamp = scan.header.stamp;
  // Every cell the scan changed lies in the core's touched box (finest cells, in metres here).
  const double res = map_.resolution();
  publisher_->touched({static_cast<double>(st.touched.min_x) * res,
                       static_cast<double>(st.touched.min_y) * res,
                       static_cast<double>(st.touched.max_x) * res,
                       static_cast<double>(st.touched.max_y) * res});
  publisher_->sensorAt(pose.x, pose.y);
}

void MappingRos::Impl::dropLocked(Input* in, DropReason reason, const std::string& detail) {
  const std::uint64_t n = ++in->c[droppedCounter(reason)];
  warnLocked(in, static_cast<std::size_t>(reason),
             "scan dropped (" + std::string(toString(reason)) + ", " + std::to_string(n) +
                 " so far): " + detail);
}

void MappingRos::Impl::caught(const char* where, const char* what, Input* in) {
  std::uint64_t n = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    n = ++exceptions_;
    if (in != nullptr) ++in->c[droppedCounter(DropReason::kException)];
  }
  ROS_ERROR_THROTTLE(kWarnPeriod, "%s: exception caught in the %s (%llu so far), going on: %s",
                     pnh_.getNamespace().c_str(), where, static_cast<unsigned long long>(n), what);
}

void MappingRos::Impl::warnLocked(Input* in, std::size_t slot, const std::string& text) {
  const ros::WallTime now = ros::WallTime::now();
  if (!in->last_warn[slot].isZero() && (now - in->last_warn[slot]).toSec() < kWarnPeriod) return;
  in->last_warn[slot] = now;
  ROS_WARN("%s: %s", in->topic.c_str(), text.c_str());
}

}  // namespace wavog_ros
