// The counters of one LaserScan input and the one table that names them: the ~status message
// (InputStatus fields) and /diagnostics (labels) are both written from it, so the two cannot list
// different counters. Plain values; the caller (MappingRos) guards them with its lock.
#ifndef WAVOG_MAPPING_SRC_ROS_INPUT_STATUS_H_
#define WAVOG_MAPPING_SRC_ROS_INPUT_STATUS_H_

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <ros/time.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include "wavog_mapping/InputStatus.h"
#include "wavog_mapping/ros/conversions.h"

namespace wavog_ros {

/// Every counter of an input, in msg/InputStatus.msg order. The dropped ones follow DropReason.
enum class Counter : std::size_t {
  kReceived,
  kIntegrated,
  kLost,          ///< never received: gaps in header.seq (SeqGapCounter)
  kDroppedFirst,  ///< + DropReason: dropped_empty ... dropped_bad_geometry
  kTimeJumps = kDroppedFirst + kNumDropReasons,
  kMotionFallbacks,
  kIntegratedLatestTf,  ///< integrated with the latest tf when the input stopped (end of a bag)
  kBeamCountMismatches,  ///< range count disagrees with the angles (integrated all the same)
  kIntensitiesIgnored,   ///< intensities of another length than ranges
  // The core's IntegrateStats, summed over the scans it was given.
  kBeamsHit,
  kBeamsInvalid,
  kBeamsNoReturn,
  kBeamsBeyondLimit,
  kNodesVisited,
  kBlocksTouched,
};
constexpr std::size_t kNumCounters = static_cast<std::size_t>(Counter::kBlocksTouched) + 1;

/// The counter of scans dropped for `reason`.
constexpr Counter droppedCounter(DropReason reason) {
  return static_cast<Counter>(static_cast<std::size_t>(Counter::kDroppedFirst) +
                              static_cast<std::size_t>(reason));
}

/// Scans lost before the node received them (roscpp's subscriber queue drops the oldest scan when
/// the node is slower than the input, and tells nobody), from the gaps in header.seq of what is
/// received. Drivers and rosbag keep seq; a publisher whose seq is always 0, or does not increase
/// by 1, must not produce false counts: a gap counts only once seq has increased by exactly 1 on
/// the same connection, and trust is lost again when seq stands still or goes back (a restarted
/// bag or driver) or the connection changes (another publisher, a reconnect).
class SeqGapCounter {
 public:
  /// A forward step larger than this is a restart (a new seq base), not a loss.
  static constexpr std::uint32_t kMaxGap = 100000;

  /// The next received scan: its seq and an opaque id of the connection it came through (the
  /// address of roscpp's connection header, never dereferenced: reading that map races with
  /// roscpp's threads). Returns how many scans are missing between the previous one and this one
  /// (0 while seq is not trusted).
  std::uint32_t next(std::uint32_t seq, std::uintptr_t connection);

 private:
  bool have_ = false;     ///< a previous scan was seen
  bool trusted_ = false;  ///< seq increased by exactly 1 since the last reset
  std::uint32_t last_ = 0;
  std::uintptr_t connection_ = 0;
};

/// Counters and clocks of one input since start-up.
struct InputCounters {
  std::array<std::uint64_t, kNumCounters> count{};
  std::uint64_t received_in_period = 0;  ///< for the measured rate in ~status
  ros::Time last_stamp;                  ///< of the last integrated scan
  ros::Time last_received_stamp;         ///< of the last received scan (time-jump check)
  ros::Time last_receipt;                ///< clock time of the last receipt (stale check)
  double rate = 0.0;                     ///< measured over the last status period (Hz)
  SeqGapCounter seq;                     ///< Counter::kLost from header.seq

  std::uint64_t& operator[](Counter c) { return count[static_cast<std::size_t>(c)]; }
  std::uint64_t operator[](Counter c) const { return count[static_cast<std::size_t>(c)]; }
  /// Scans dropped for any reason.
  std::uint64_t dropped() const;
  /// Scans dropped because tf was unavailable or too old (MapperStatus::tf_failures).
  std::uint64_t tfFailures() const;
};

/// The ~status entry of one input: every counter of the table, the stamps and the rates.
wavog_mapping::InputStatus toInputStatus(const InputCounters& c, const std::string& topic,
                                         double expected_rate);

/// Adds every counter of the table to a diagnostic status ("received", "dropped empty", ...),
/// then the total "dropped".
void addCounters(const InputCounters& c, diagnostic_updater::DiagnosticStatusWrapper* stat);

}  // namespace wavog_ros

#endif  // WAVOG_MAPPING_SRC_ROS_INPUT_STATUS_H_
