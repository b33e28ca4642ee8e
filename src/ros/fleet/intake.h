// The fleet node's intake of one delivered PlacedScan, before the reorder buffer: counted as
// received, its index stepped (stream_index.h: lost, regressions, jumps), then checked
// (placed_scan.h) and a refusal counted by reason. No roscore needed (message types, ros::Time),
// so that the fuzz harness (test/fuzz/fuzz_fleet.cpp) drives the node's own counting.
// Not thread-safe (the caller's lock).
#ifndef WAVOG_MAPPING_SRC_ROS_FLEET_INTAKE_H_
#define WAVOG_MAPPING_SRC_ROS_FLEET_INTAKE_H_

#include <ros/time.h>

#include <cstdint>
#include <string>

#include "placed_scan.h"
#include "stream_index.h"
#include "wavog_mapping/PlacedScan.h"
#include "wavog_mapping/VehicleStatus.h"

namespace wavog_fleet {

/// What the intake did with one message.
struct Intake {
  IndexStep step = IndexStep::kFirst;  ///< what its index did to the vehicle's sequence
  Refusal refusal = Refusal::kNone;    ///< kNone: it goes on to the reorder buffer
  std::string detail;                  ///< what was wrong (a refusal)
};

/// Counts message `m` of one vehicle (`index`: its sequence, `c`: its counters) delivered at the
/// fleet clock's `now`: received and bytes, lost / index_regressions / index_jumps, and
/// dropped_<reason> when checkPlacedScan() refuses it. Never throws.
Intake takeIn(const wavog_mapping::PlacedScan& m, const PlacedScanLimits& limits,
              const ros::Time& now, StreamIndex* index, wavog_mapping::VehicleStatus* c);

/// Counts a message of `length` bytes refused before deserialisation (checked_subscription.h:
/// an array longer than its bytes, or truncated) as received, its bytes, and dropped_bad_length;
/// `partial` holds the fields read before the refusal, its first `bytes_read` bytes: when they
/// include `index`, the index steps the sequence as takeIn() steps it (the message was delivered,
/// so it is not lost). Never throws.
Intake takeInRefused(const wavog_mapping::PlacedScan& partial, std::uint32_t bytes_read,
                     std::uint32_t length, const std::string& why, StreamIndex* index,
                     wavog_mapping::VehicleStatus* c);

/// Bytes of a serialised PlacedScan up to the end of its `index` field, for `m`'s strings.
std::uint64_t bytesThroughIndex(const wavog_mapping::PlacedScan& m);

/// The counter of refusal `r` (kNone: nullptr).
std::uint64_t* refusalCounter(Refusal r, wavog_mapping::VehicleStatus* c);

}  // namespace wavog_fleet

#endif  // WAVOG_MAPPING_SRC_ROS_FLEET_INTAKE_H_
