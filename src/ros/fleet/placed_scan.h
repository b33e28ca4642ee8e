// PlacedScan (msg/PlacedScan.msg): a scan exactly as a mapper's core integrated it. One side
// fills it from the core call (mapper, fleet_stream: true), the other checks it and gets the very
// same core call back (fleet node): integrate(placedPose(m), placedView(m)) is bit for bit the
// mapper's integrate(pose, view). Reentrant.
#ifndef WAVOG_MAPPING_SRC_ROS_FLEET_PLACED_SCAN_H_
#define WAVOG_MAPPING_SRC_ROS_FLEET_PLACED_SCAN_H_

#include <ros/time.h>

#include <cstddef>
#include <string>

#include "wavog_mapping/PlacedScan.h"
#include "wavog_mapping/core/types.h"

namespace wavog_fleet {

/// Why a fleet node refuses a PlacedScan (before the core sees it). Order = VehicleStatus fields.
enum class Refusal {
  kNone,
  kVersion,  ///< another format version
  kFrame,    ///< not in the fleet's map frame
  kBadPose,  ///< non-finite pose or angles, zero stamp
  kBadSize,  ///< no beams, too many beams, bad range limits
};
const char* toString(Refusal r);

/// Fills everything but header.seq: the scan stamped `stamp` of `input`, integrated from `pose`
/// with `view` (the beams after mirroring and motion compensation), placed between `start` and
/// `end` (equal without compensation).
void fillPlacedScan(const ros::Time& stamp, const std::string& map_frame,
                    const std::string& vehicle, const std::string& input, std::uint64_t index,
                    const wavog::Pose2& pose, const wavog::ScanView& view, bool compensated,
                    const wavog::Pose2& start, const wavog::Pose2& end,
                    wavog_mapping::PlacedScan* m);

/// Checks a received PlacedScan against the fleet's `map_frame`; kNone: usable.
Refusal checkPlacedScan(const wavog_mapping::PlacedScan& m, const std::string& map_frame,
                        std::string* detail);

/// The core call's arguments; `m` must outlive the view.
wavog::Pose2 placedPose(const wavog_mapping::PlacedScan& m);
wavog::ScanView placedView(const wavog_mapping::PlacedScan& m);

}  // namespace wavog_fleet

#endif  // WAVOG_MAPPING_SRC_ROS_FLEET_PLACED_SCAN_H_
