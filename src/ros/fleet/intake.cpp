// The fleet node's intake of one delivered PlacedScan (see intake.h).
#include "intake.h"

#include <ros/serialization.h>

namespace wavog_fleet {

std::uint64_t* refusalCounter(Refusal r, wavog_mapping::VehicleStatus* c) {
  switch (r) {
    case Refusal::kVersion:
      return &c->dropped_version;
    case Refusal::kFrame:
      return &c->dropped_frame;
    case Refusal::kBadStamp:
      return &c->dropped_bad_stamp;
    case Refusal::kBadPose:
      return &c->dropped_bad_pose;
    case Refusal::kBadSize:
      return &c->dropped_bad_size;
    case Refusal::kNone:
      break;
  }
  return nullptr;
}

Intake takeIn(const wavog_mapping::PlacedScan& m, const PlacedScanLimits& limits,
              const ros::Time& now, StreamIndex* index, wavog_mapping::VehicleStatus* c) {
  Intake in;
  ++c->received;
  c->bytes = saturatingAdd(c->bytes, ros::serialization::serializationLength(m));
  // The index first: a message refused below was delivered, so it is not lost.
  std::uint64_t skipped = 0;
  in.step = index->step(m.index, &skipped);
  switch (in.step) {
    case IndexStep::kGap:
      c->lost = saturatingAdd(c->lost, skipped);
      break;
    case IndexStep::kRegress:
      ++c->index_regressions;
      break;
    case IndexStep::kJump:
      ++c->index_jumps;
      break;
    case IndexStep::kFirst:
    case IndexStep::kNext:
      break;
  }
  in.refusal = checkPlacedScan(m, limits, now, &in.detail);
  if (std::uint64_t* counter = refusalCounter(in.refusal, c)) ++*counter;
  return in;
}

}  // namespace wavog_fleet
