// Scan placement: the one path from a LaserScan and tf to the pose and view the core integrates,
// shared by MappingRos and wavog_offline. Two tf lookups per scan (first and last beam), never one
// per beam; an upside-down laser mirrors the view; the sweep is re-binned at its middle pose when
// the scan times its beams. Fixed frame, metres, radians. Thread-safety: placeScan() only reads the
// (self-locking) tf buffer and is reentrant; ScanPlacement::placedView() writes the compensator it
// is given (one compensator per thread, or under the caller's lock).
#ifndef WAVOG_MAPPING_ROS_SCAN_PLACEMENT_H_
#define WAVOG_MAPPING_ROS_SCAN_PLACEMENT_H_

#include <sensor_msgs/LaserScan.h>
#include <tf2/buffer_core.h>

#include <string>

#include "wavog_mapping/core/motion_compensation.h"
#include "wavog_mapping/core/types.h"

namespace wavog_ros {

/// How scans are placed.
struct PlacementOptions {
  /// Frame the map lives in (tf2 frame id, no leading '/'). A scan in this very frame is held
  /// fixed at the origin: no lookup, no motion compensation.
  std::string fixed_frame = "map";
  /// Re-bin each sweep with the sensor pose interpolated between its first and last beam (needs
  /// time_increment and tf at the last beam; without the latter the scan is placed uncompensated).
  bool motion_compensation = true;
};

/// Why tf could not place a scan.
enum class TfFailure {
  kNone,           ///< placed
  kUnavailable,    ///< an unknown frame, or frames that tf never connects
  kExtrapolation,  ///< tf connects the frames, but not at the scan's stamp
};

/// Where one scan was measured from, as tf says. Stamps: the scan's stamp for the first beam,
/// stamp + time_increment * (count - 1) for the last.
struct ScanPlacement {
  TfFailure failure = TfFailure::kNone;
  std::string error;      ///< tf's message when failure != kNone
  wavog::Pose2 start;     ///< sensor pose at the first beam (fixed frame)
  wavog::Pose2 end;       ///< at the last beam; equals start unless `compensate`
  bool mirrored = false;  ///< the laser's z axis points down: its bearings are mirrored
  bool compensate = false;       ///< start and end both known: the sweep is re-binned
  bool motion_fallback = false;  ///< compensation wanted, but no tf at the last beam
  /// Of motion_fallback: the sweep is valid but tf did not cover its last beam (yet). A live
  /// node waits for that tf (it may still come); an invalid sweep never waits.
  bool end_missing = false;

  bool placed() const { return failure == TfFailure::kNone; }

  /// The view of `scan` (which must outlive it) and the pose to integrate it with: mirrored when
  /// needed, and re-binned into the middle pose of the sweep when `compensate` (the view then
  /// points into *compensator until its next use). Requires placed().
  wavog::ScanView placedView(const sensor_msgs::LaserScan& scan,
                             wavog::MotionCompensator* compensator, wavog::Pose2* pose) const;
};

/// The stamp of the last beam of a scan that passed checkScan(), when `options` compensate its
/// motion: false when they do not (compensation off, fewer than 2 beams, no time_increment, the
/// scan in the fixed frame) or its sweep is not representable.
bool sweepEndStamp(const sensor_msgs::LaserScan& scan, const PlacementOptions& options,
                   ros::Time* end);

/// Looks up the sensor pose of a scan that passed checkScan() (conversions.h) in `tf`, at its
/// first beam and, with motion compensation, at its last. Never throws: a failed first lookup
/// is reported in `failure` and `error`; a failed last lookup only sets motion_fallback.
ScanPlacement placeScan(const tf2::BufferCore& tf, const sensor_msgs::LaserScan& scan,
                        const PlacementOptions& options);

}  // namespace wavog_ros

#endif  // WAVOG_MAPPING_ROS_SCAN_PLACEMENT_H_
