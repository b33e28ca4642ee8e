// Motion compensation of one planar sweep (and the reach of a scan): beams measured while the
// sensor moved are re-expressed in one reference pose and re-binned onto the scan's angular grid,
// so that the result can go to WaveletMap::integrate(reference, view). Map frame, metres, radians.
// Not thread-safe (one compensator per thread; it reuses its buffer).
#ifndef WAVOG_MAPPING_CORE_MOTION_COMPENSATION_H_
#define WAVOG_MAPPING_CORE_MOTION_COMPENSATION_H_

#include <cstddef>
#include <vector>

#include "wavog_mapping/core/params.h"
#include "wavog_mapping/core/types.h"

namespace wavog {

/// Farthest distance (m) from the sensor at which `scan` can change the map under `sensor`: the
/// longest return (plus the occupied band), or no_return_clear when a beam has no return. Used to
/// bound the region a scan touched (e.g. for incremental map publication). 0 for an empty scan.
/// Ranges and no_return_clear are capped at kMaxRangeCells * resolution (limits.h), an upper
/// bound of the core's hard range limit.
double scanReach(const ScanView& scan, const SensorModelParams& sensor, double resolution);

/// Re-bins moving-sensor scans. Beam i is assumed to be measured at fraction i / (count - 1) of the
/// sweep (uniform time_increment), from the pose interpolated between `start` (beam 0) and `end`
/// (last beam).
class MotionCompensator {
 public:
  /// Returns the scan as seen from `reference`: same angle_min, angle_increment, count and range
  /// limits; bin j holds the nearest return whose endpoint lies in its bearing cell. Without a
  /// return, a bin keeps a "no return" value (+inf or >= range_max, as measured, rotated into the
  /// reference frame), else an invalid value as measured (REP 117), else NaN (no information).
  /// Returns land outside the field of view are dropped (counted by droppedLast()); a full-circle
  /// scan wraps around. The view points into this object and stays valid until the next call.
  /// A scan without beams, with a zero or non-finite angle_increment, or with more than kMaxBeams
  /// beams (limits.h; the core refuses it) is returned unchanged. Buffers grown beyond
  /// kScratchKeepBeams beams are released by the next smaller scan.
  ScanView compensate(const ScanView& scan, const Pose2& start, const Pose2& end,
                      const Pose2& reference);

  /// Returns dropped by the last compensate() because they left the field of view.
  std::size_t droppedLast() const { return dropped_; }

 private:
  std::vector<float> ranges_;
  std::vector<signed char> rank_;  // per bin: -1 empty, 0 invalid, 1 no return, 2 return
  std::size_t dropped_ = 0;
};

}  // namespace wavog

#endif  // WAVOG_MAPPING_CORE_MOTION_COMPENSATION_H_
