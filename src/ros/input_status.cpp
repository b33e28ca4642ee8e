// The counter table of an input (see input_status.h): one row per counter, with its ~status
// field and its /diagnostics label.
#include "input_status.h"

namespace wavog_ros {
namespace {

using wavog_mapping::InputStatus;

struct CounterRow {
  Counter counter;
  const char* label;  ///< /diagnostics key
  InputStatus::_received_type InputStatus::*field;
};

constexpr CounterRow kRows[] = {
    {Counter::kReceived, "received", &InputStatus::received},
    {Counter::kIntegrated, "integrated", &InputStatus::integrated},
    {Counter::kLost, "lost (header.seq gaps)", &InputStatus::lost},
    {droppedCounter(DropReason::kEmpty), "dropped empty", &InputStatus::dropped_empty},
    {droppedCounter(DropReason::kBadAngles), "dropped bad_angles", &InputStatus::dropped_bad_angles},
    {droppedCounter(DropReason::kBadFrame), "dropped bad_frame", &InputStatus::dropped_bad_frame},
    {droppedCounter(DropReason::kTfUnavailable), "dropped tf_unavailable",
     &InputStatus::dropped_tf_unavailable},
    {droppedCounter(DropReason::kTfTooOld), "dropped tf_too_old", &InputStatus::dropped_tf_too_old},
    {droppedCounter(DropReason::kNoValidBeam), "dropped no_valid_beam",
     &InputStatus::dropped_no_valid_beam},
    {droppedCounter(DropReason::kBadGeometry), "dropped bad_geometry",
     &InputStatus::dropped_bad_geometry},
    {droppedCounter(DropReason::kOutOfExtent), "dropped out_of_extent",
     &InputStatus::dropped_out_of_extent},
    {droppedCounter(DropReason::kAbsurdPose), "dropped absurd_pose",
     &InputStatus::dropped_absurd_pose},
    {droppedCounter(DropReason::kBadTime), "dropped bad_time", &InputStatus::dropped_bad_time},
    {droppedCounter(DropReason::kException), "dropped exception",
     &InputStatus::dropped_exception},
    {droppedCounter(DropReason::kBadLength), "dropped bad_length",
     &InputStatus::dropped_bad_length},
    {Counter::kTimeJumps, "time jumps", &InputStatus::time_jumps},
    {Counter::kMotionFallbacks, "motion fallbacks", &InputStatus::motion_fallbacks},
    {Counter::kIntegratedLatestTf, "integrated with latest tf", &InputStatus::integrated_latest_tf},
    {Counter::kBeamCountMismatches, "beam count mismatches", &InputStatus::beam_count_mismatches},
    {Counter::kIntensitiesIgnored, "intensities ignored", &InputStatus::intensities_ignored},
    {Counter::kBeamsHit, "beams hit", &InputStatus::beams_hit},
    {Counter::kBeamsInvalid, "beams invalid", &InputStatus::beams_invalid},
    {Counter::kBeamsNoReturn, "beams no return", &InputStatus::beams_no_return},
    {Counter::kBeamsBeyondLimit, "beams beyond the hard range limit",
     &InputStatus::beams_beyond_limit},
    {Counter::kNodesVisited, "nodes visited", &InputStatus::nodes_visited},
    {Counter::kBlocksTouched, "blocks touched", &InputStatus::blocks_touched},
};
static_assert(sizeof(kRows) / sizeof(kRows[0]) == kNumCounters, "one row per counter");

constexpr bool rowsInCounterOrder() {
  for (std::size_t i = 0; i < kNumCounters; ++i) {
    if (static_cast<std::size_t>(kRows[i].counter) != i) return false;
  }
  return true;
}
static_assert(rowsInCounterOrder(), "row i is counter i");

}  // namespace

std::uint32_t SeqGapCounter::next(std::uint32_t seq, std::uintptr_t connection) {
  if (!have_ || connection != connection_) {
    have_ = true;
    trusted_ = false;
    last_ = seq;
    connection_ = connection;
    return 0;
  }
  const std::uint32_t step = seq - last_;  // modulo 2^32: a wrap-around is a step of 1
  last_ = seq;
  if (step == 1) {
    trusted_ = true;
    return 0;
  }
  if (step == 0 || step > kMaxGap) {  // standing still, going back, or a new base
    trusted_ = false;
    return 0;
  }
  return trusted_ ? step - 1 : 0;
}

std::uint64_t InputCounters::dropped() const {
  std::uint64_t n = 0;
  for (std::size_t r = 0; r < kNumDropReasons; ++r) {
    n += (*this)[droppedCounter(static_cast<DropReason>(r))];
  }
  return n;
}

std::uint64_t InputCounters::tfFailures() const {
  return (*this)[droppedCounter(DropReason::kTfUnavailable)] +
         (*this)[droppedCounter(DropReason::kTfTooOld)];
}

InputStatus toInputStatus(const InputCounters& c, const std::string& topic,
                          double expected_rate) {
  InputStatus s;
  s.topic = topic;
  for (const CounterRow& row : kRows) s.*row.field = c[row.counter];
  s.last_stamp = c.last_stamp;
  s.rate = c.rate;
  s.expected_rate = expected_rate;
  return s;
}

void addCounters(const InputCounters& c, diagnostic_updater::DiagnosticStatusWrapper* stat) {
  for (const CounterRow& row : kRows) stat->add(row.label, c[row.counter]);
  stat->add("dropped", c.dropped());
}

}  // namespace wavog_ros
