// The fleet node's intake of a vehicle's messages without a master (intake.h, issue 37): every
// delivered message is received, refused ones by their reason and never as lost, `lost` counts
// exactly the indices the stream skipped, a duplicate or regressing index and a jump beyond 2^32
// are counted on their own, and no index makes a counter wrap.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "fleet/intake.h"
#include "fleet/placed_scan.h"
#include "fleet/stream_index.h"
#include "placed_scan_fixture.h"

namespace {

using placed_scan_fixture::goodScan;
using wavog_fleet::IndexStep;
using wavog_fleet::Refusal;

const ros::Time kNow(100.0);  // the fleet clock, goodScan()'s stamp

struct Stream {
  wavog_fleet::StreamIndex index;
  wavog_mapping::VehicleStatus c;
  wavog_fleet::Intake take(const wavog_mapping::PlacedScan& m) {
    return wavog_fleet::takeIn(m, wavog_fleet::PlacedScanLimits{}, kNow, &index, &c);
  }
};

TEST(FleetIntake, RefusedMessagesAreDeliveredNotLost) {
  Stream s;
  EXPECT_EQ(s.take(goodScan(0)).refusal, Refusal::kNone);
  // Indices 1..6, each refused by a check: all delivered.
  auto m = goodScan(1);
  m.version = 7;
  EXPECT_EQ(s.take(m).refusal, Refusal::kVersion);
  m = goodScan(2);
  m.header.frame_id = "odom";
  EXPECT_EQ(s.take(m).refusal, Refusal::kFrame);
  m = goodScan(3);
  m.header.stamp = kNow + ros::Duration(1e6);  // 11 days ahead
  EXPECT_EQ(s.take(m).refusal, Refusal::kBadStamp);
  m = goodScan(4);
  m.end_x = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(s.take(m).refusal, Refusal::kBadPose);
  m = goodScan(5);
  m.angle_increment = 1e-310;
  EXPECT_EQ(s.take(m).refusal, Refusal::kBadSize);
  m = goodScan(6);
  m.period = 1e300;  // under forget_half_life: every cell of its fan forgotten at once
  EXPECT_EQ(s.take(m).refusal, Refusal::kBadSize);
  const wavog_fleet::Intake last = s.take(goodScan(7));
  EXPECT_EQ(last.refusal, Refusal::kNone);
  EXPECT_EQ(last.step, IndexStep::kNext);
  EXPECT_EQ(s.c.received, 8u);
  EXPECT_GT(s.c.bytes, 8u * 181u * 4u);
  EXPECT_EQ(s.c.lost, 0u);
  EXPECT_EQ(s.c.dropped_bad_size, 2u);
  EXPECT_EQ(s.c.dropped_version + s.c.dropped_frame + s.c.dropped_bad_stamp +
                s.c.dropped_bad_pose + s.c.dropped_bad_size,
            6u);
  EXPECT_EQ(s.c.index_regressions + s.c.index_jumps, 0u);
}

TEST(FleetIntake, LostCountsExactlyTheSkippedIndices) {
  Stream s;
  s.take(goodScan(10));  // a stream may start anywhere (a fleet node started late)
  EXPECT_EQ(s.take(goodScan(13)).step, IndexStep::kGap);
  EXPECT_EQ(s.c.lost, 2u);
  // A duplicate and a regression (a restarted mapper): counted, not lost; the sequence goes on.
  EXPECT_EQ(s.take(goodScan(13)).step, IndexStep::kRegress);
  EXPECT_EQ(s.take(goodScan(0)).step, IndexStep::kRegress);
  EXPECT_EQ(s.take(goodScan(1)).step, IndexStep::kNext);
  EXPECT_EQ(s.c.index_regressions, 2u);
  EXPECT_EQ(s.c.lost, 2u);
  // The largest gap still counted as lost, then a corrupt index (2^64 - 1) is a jump.
  EXPECT_EQ(s.take(goodScan(2 + wavog_fleet::kMaxIndexGap)).step, IndexStep::kGap);
  EXPECT_EQ(s.c.lost, 2u + wavog_fleet::kMaxIndexGap);
  EXPECT_EQ(s.take(goodScan(std::numeric_limits<std::uint64_t>::max())).step, IndexStep::kJump);
  EXPECT_EQ(s.c.index_jumps, 1u);
  EXPECT_EQ(s.c.lost, 2u + wavog_fleet::kMaxIndexGap) << "a jump adds nothing to lost";
  // After 2^64 - 1 every index regresses; nothing wraps.
  EXPECT_EQ(s.take(goodScan(0)).step, IndexStep::kRegress);
  EXPECT_EQ(s.c.received, 8u);
}

TEST(FleetIntake, LostSaturates) {
  EXPECT_EQ(wavog_fleet::saturatingAdd(std::numeric_limits<std::uint64_t>::max() - 1, 5),
            std::numeric_limits<std::uint64_t>::max());
  EXPECT_EQ(wavog_fleet::saturatingAdd(3, 4), 7u);
}

TEST(FleetIntake, BothStreamVersionsAreReadAndAnyOtherRefused) {
  Stream s;
  const auto floats = goodScan(0);
  const auto codes = goodScan(1, true);
  EXPECT_EQ(floats.version, wavog_mapping::PlacedScan::VERSION_FLOAT32);
  EXPECT_EQ(codes.version, wavog_mapping::PlacedScan::VERSION_UINT16);
  EXPECT_EQ(codes.range_codes.size(), 181u);
  EXPECT_TRUE(codes.ranges.empty());
  EXPECT_EQ(codes.range_step, 80.0 / wavog_fleet::kMaxHitCode);  // range_max 80 m: 1.22 mm
  EXPECT_EQ(s.take(floats).refusal, Refusal::kNone);
  const std::uint64_t float_bytes = s.c.bytes;
  EXPECT_EQ(s.take(codes).refusal, Refusal::kNone);
  // 181 beams: 2 bytes each instead of 4 (both versions carry both arrays' lengths and the step).
  EXPECT_EQ(s.c.bytes - float_bytes, float_bytes - 181u * 2u);
  // The codes decode to the ranges the mapper integrated.
  std::vector<float> decoded;
  const wavog::ScanView v = wavog_fleet::placedView(codes, &decoded);
  ASSERT_EQ(v.count, 181u);
  EXPECT_EQ(v.ranges, decoded.data());
  EXPECT_NEAR(v.ranges[0], 5.0f, 0.5 * codes.range_step);
  // Any other version is refused, whichever array it fills.
  for (const std::uint8_t version : {0, 3, 255}) {
    auto m = goodScan(2, version == 3);
    m.version = version;
    EXPECT_EQ(s.take(m).refusal, Refusal::kVersion) << int{version};
  }
  // A version's ranges in the other array, or both, or a step no mapper sends: bad size.
  auto m = goodScan(5, true);
  m.version = wavog_mapping::PlacedScan::VERSION_FLOAT32;  // codes under version 1
  EXPECT_EQ(s.take(m).refusal, Refusal::kBadSize);
  m = goodScan(6);
  m.version = wavog_mapping::PlacedScan::VERSION_UINT16;  // floats under version 2
  EXPECT_EQ(s.take(m).refusal, Refusal::kBadSize);
  m = goodScan(7, true);
  m.ranges.assign(181, 5.0f);  // both
  EXPECT_EQ(s.take(m).refusal, Refusal::kBadSize);
  for (const double step : {0.0, 1e-4, -0.001, std::nan(""), 1e3}) {
    m = goodScan(8, true);
    m.range_step = step;
    EXPECT_EQ(s.take(m).refusal, Refusal::kBadSize) << step;
  }
  EXPECT_EQ(s.c.dropped_version, 3u);
  EXPECT_EQ(s.c.dropped_bad_size, 8u);
}

}  // namespace

namespace {

// Issue 42: a message refused before deserialisation (an array longer than its bytes) is
// delivered too: its index, when it was read, steps the sequence; one cut before its index does
// not (the next message's gap then counts it as lost, as nothing says which index it had).
TEST(FleetIntake, MessagesRefusedForTheirLengthAreDeliveredWhenTheirIndexWasRead) {
  Stream s;
  EXPECT_EQ(s.take(goodScan(0)).refusal, Refusal::kNone);
  wavog_mapping::PlacedScan partial = goodScan(1);
  partial.ranges.clear();  // as read up to the forged prefix
  const std::uint64_t through_index = wavog_fleet::bytesThroughIndex(partial);
  EXPECT_EQ(through_index, 1u + 12u + 4u + 3u + 4u + 2u + 4u + 8u + 8u);  // "map", "v1", "/v1/scan"
  const wavog_fleet::Intake in =
      wavog_fleet::takeInRefused(partial, static_cast<std::uint32_t>(through_index) + 100, 1600,
                                 "an array claims", &s.index, &s.c);
  EXPECT_EQ(in.refusal, Refusal::kBadLength);
  EXPECT_EQ(in.step, IndexStep::kNext);
  EXPECT_EQ(in.detail, "an array claims");
  EXPECT_EQ(s.c.dropped_bad_length, 1u);
  EXPECT_EQ(s.c.received, 2u);
  EXPECT_EQ(s.c.bytes, ros::serialization::serializationLength(goodScan(0)) + 1600u);
  // Cut inside its input string: index 2 not read, not stepped.
  wavog_mapping::PlacedScan cut = goodScan(2);
  cut.input.clear();
  cut.index = 0;
  wavog_fleet::takeInRefused(cut, static_cast<std::uint32_t>(through_index) - 12, 40, "ends",
                             &s.index, &s.c);
  EXPECT_EQ(s.c.dropped_bad_length, 2u);
  EXPECT_EQ(s.c.index_regressions, 0u);  // the 0 it holds was not taken for an index
  EXPECT_EQ(s.take(goodScan(3)).step, IndexStep::kGap);
  EXPECT_EQ(s.c.lost, 1u);
  EXPECT_EQ(s.c.received, 4u);
}

}  // namespace
