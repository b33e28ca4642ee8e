// Scan placement (see scan_placement.h): tf lookups at the first and last beam, then the view the
// core integrates (mirrored, motion-compensated).
#include "wavog_mapping/ros/scan_placement.h"

#include <tf2/exceptions.h>

#include <cmath>

#include "wavog_mapping/ros/conversions.h"

namespace wavog_ros {

namespace {

/// The options compensate the scan's motion, and the scan times its beams.
bool wantsCompensation(const sensor_msgs::LaserScan& scan, const PlacementOptions& options) {
  return options.motion_compensation && scan.header.frame_id != options.fixed_frame &&
         scan.ranges.size() >= 2 && std::isfinite(scan.time_increment) &&
         scan.time_increment != 0.0f;
}

}  // namespace

bool sweepEndStamp(const sensor_msgs::LaserScan& scan, const PlacementOptions& options,
                   ros::Time* end) {
  if (!wantsCompensation(scan, options)) return false;
  // checkScanTime() refuses the sweeps ROS time cannot represent; here they only skip the
  // compensation, so that placeScan() never throws.
  return std::abs(sweepSeconds(scan)) <= kMaxSweepSeconds &&
         addSeconds(scan.header.stamp, sweepSeconds(scan), end);
}

ScanPlacement placeScan(const tf2::BufferCore& tf, const sensor_msgs::LaserScan& scan,
                        const PlacementOptions& options) {
  ScanPlacement p;
  const std::string& frame = scan.header.frame_id;
  // A laser that is the fixed frame cannot move in it: identity, nothing to compensate.
  if (frame == options.fixed_frame) return p;
  try {
    p.start =
        toPose2(tf.lookupTransform(options.fixed_frame, frame, scan.header.stamp).transform,
                &p.mirrored);
  } catch (const tf2::ExtrapolationException& e) {
    p.failure = TfFailure::kExtrapolation;
    p.error = e.what();
    return p;
  } catch (const std::exception& e) {  // tf2::TransformException, or anything tf throws
    p.failure = TfFailure::kUnavailable;
    p.error = e.what();
    return p;
  }
  p.end = p.start;
  if (!wantsCompensation(scan, options)) return p;
  ros::Time end_stamp;
  if (!sweepEndStamp(scan, options, &end_stamp)) {
    p.motion_fallback = true;
    return p;
  }
  try {
    bool mirrored_end = false;
    p.end = toPose2(tf.lookupTransform(options.fixed_frame, frame, end_stamp).transform,
                    &mirrored_end);
    p.compensate = true;
  } catch (const std::exception&) {
    p.end = p.start;
    p.motion_fallback = true;
    p.end_missing = true;
  }
  return p;
}

wavog::ScanView ScanPlacement::placedView(const sensor_msgs::LaserScan& scan,
                                          wavog::MotionCompensator* compensator,
                                          wavog::Pose2* pose) const {
  wavog::ScanView view = toScanView(scan);
  if (mirrored) mirrorView(&view);
  *pose = start;
  if (!compensate) return view;
  *pose = wavog::interpolate(start, end, 0.5);
  return compensator->compensate(view, start, end, *pose);
}

}  // namespace wavog_ros
