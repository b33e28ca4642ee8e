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
    case Refusal::kBadLength:
      return &c->dropped_bad_length;
    case Refusal::kNone:
      break;
  }
  return nullptr;
}

namespace {

/// Steps the vehicle's sequence by `m_index` and counts what it did.
IndexStep stepIndex(std::uint64_t m_index, StreamIndex* index, wavog_mapping::VehicleStatus* c) {
  std::uint64_t skipped = 0;
  const IndexStep step = index->step(m_index, &skipped);
  switch (step) {
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
  return step;
}

}  // namespace

Intake takeIn(const wavog_mapping::PlacedScan& m, const PlacedScanLimits& limits,
              const ros::Time& now, StreamIndex* index, wavog_mapping::VehicleStatus* c) {
  Intake in;
  ++c->received;
  c->bytes = saturatingAdd(c->bytes, ros::serialization::serializationLength(m));
  // The index first: a message refused below was delivered, so it is not lost.
  in.step = stepIndex(m.index, index, c);
  in.refusal = checkPlacedScan(m, limits, now, &in.detail);
  if (std::uint64_t* counter = refusalCounter(in.refusal, c)) ++*counter;
  return in;
}

std::uint64_t bytesThroughIndex(const wavog_mapping::PlacedScan& m) {
  // version, header (seq, stamp, frame_id), vehicle, input, index
  return 1u + 4u + 8u + 4u + m.header.frame_id.size() + 4u + m.vehicle.size() + 4u +
         m.input.size() + 8u;
}

Intake takeInRefused(const wavog_mapping::PlacedScan& partial, std::uint32_t bytes_read,
                     std::uint32_t length, const std::string& why, StreamIndex* index,
                     wavog_mapping::VehicleStatus* c) {
  Intake in;
  ++c->received;
  c->bytes = saturatingAdd(c->bytes, length);
  // A string not read is empty here, and bytes_read then ends before it: the sum cannot reach it.
  if (bytes_read >= bytesThroughIndex(partial)) in.step = stepIndex(partial.index, index, c);
  in.refusal = Refusal::kBadLength;
  in.detail = why;
  ++c->dropped_bad_length;
  return in;
}

}  // namespace wavog_fleet
