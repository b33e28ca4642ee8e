// PlacedScan (msg/PlacedScan.msg): a scan exactly as a mapper's core integrated it. One side
// fills it from the core call (mapper, fleet_stream: true), the other checks it and gets the very
// same core call back (fleet node): integrate(placedPose(m), placedView(m, &buffer)) is bit for
// bit the mapper's integrate(pose, view), in either version (float32 ranges, or 16-bit codes the
// mapper integrated decoded: range_codec.h). Reentrant.
#ifndef WAVOG_MAPPING_SRC_ROS_FLEET_PLACED_SCAN_H_
#define WAVOG_MAPPING_SRC_ROS_FLEET_PLACED_SCAN_H_

#include <ros/time.h>

#include <cstddef>
#include <string>

#include <vector>

#include "range_codec.h"
#include "wavog_mapping/PlacedScan.h"
#include "wavog_mapping/core/types.h"

namespace wavog_fleet {

/// Why a fleet node refuses a PlacedScan (before the core sees it), checked in this order; each
/// one is a VehicleStatus counter (dropped_<name>). The limits: docs/fleet.md.
enum class Refusal {
  kNone,
  kVersion,   ///< a format version other than 1 (float32 ranges) and 2 (16-bit codes)
  kFrame,     ///< not in the fleet's map frame
  kBadStamp,  ///< stamp 0, nsec >= 1e9, or farther than max_stamp_offset from the fleet's clock
  kBadPose,   ///< a pose field (x, y, theta, start_*, end_*) not finite or outside the limits
  kBadSize,   ///< the scan geometry outside the core's limits (beams, angles, range limits),
              ///< ranges not as its version has them (the other array filled, a range_step
              ///< outside [kRangeStep, kMaxRangeStep]), or a period outside
              ///< [0, ScanPeriod::kMaxPeriod] (none a mapper sends)
  /// An array longer than the message's bytes, or a truncated message: refused before
  /// deserialisation (checked_subscription.h).
  kBadLength,
};
const char* toString(Refusal r);

/// What checkPlacedScan() holds a message against.
struct PlacedScanLimits {
  std::string map_frame = "map";  ///< the fleet's map frame
  /// The fleet map's cell size (m): a pose coordinate must lie in the core's extent,
  /// |x| / resolution < kCellIndexLimit (limits.h).
  double resolution = 0.05;
  /// Largest |stamp - the fleet node's clock| (s), fleet_max_stamp_offset.
  double max_stamp_offset = 60.0;
};

/// Fills everything but header.seq: the scan stamped `stamp` of `input`, integrated from `pose`
/// with `view` (the beams after mirroring and motion compensation), placed between `start` and
/// `end` (equal without compensation). `codes` null: version 1, the ranges of `view` as float32;
/// else version 2, its codes (which encoded `view`; the view then holds codes->decoded()).
void fillPlacedScan(const ros::Time& stamp, const std::string& map_frame,
                    const std::string& vehicle, const std::string& input, std::uint64_t index,
                    const wavog::Pose2& pose, const wavog::ScanView& view, bool compensated,
                    const wavog::Pose2& start, const wavog::Pose2& end,
                    wavog_mapping::PlacedScan* m, const RangeCodec* codes = nullptr);

/// Checks a received PlacedScan against `limits` at the fleet clock's `now`; kNone: usable
/// (then every stamp arithmetic of the fleet node on it fits ros::Time and ros::Duration).
/// *detail (if not null): what was wrong, empty for kNone. Never throws.
Refusal checkPlacedScan(const wavog_mapping::PlacedScan& m, const PlacedScanLimits& limits,
                        const ros::Time& now, std::string* detail);

/// The core call's arguments of a checked message; the view points into `m` (version 1) or into
/// *decoded (version 2, its codes decoded there), which must outlive it.
wavog::Pose2 placedPose(const wavog_mapping::PlacedScan& m);
wavog::ScanView placedView(const wavog_mapping::PlacedScan& m, std::vector<float>* decoded);
/// The beams of `m` in its version's array.
std::size_t placedBeams(const wavog_mapping::PlacedScan& m);

}  // namespace wavog_fleet

#endif  // WAVOG_MAPPING_SRC_ROS_FLEET_PLACED_SCAN_H_
