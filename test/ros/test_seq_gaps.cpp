// SeqGapCounter (src/ros/input_status.h): scans lost before the node received them, from the gaps
// in header.seq; no false counts from publishers whose seq is 0, not increasing by 1, restarted or
// shared by two publishers. No master needed.
#include <gtest/gtest.h>

#include <cstdint>
#include <initializer_list>

#include "../../src/ros/input_status.h"

namespace {

using wavog_ros::SeqGapCounter;

// Connection ids (SeqGapCounter::next takes them as opaque numbers).
constexpr std::uintptr_t kDriver = 1, kA = 2, kB = 3;

/// Feeds `seqs` from `publisher`; returns the scans counted as lost.
std::uint64_t feed(SeqGapCounter* c, std::initializer_list<std::uint32_t> seqs,
                   std::uintptr_t connection = kDriver) {
  std::uint64_t lost = 0;
  for (const std::uint32_t s : seqs) lost += c->next(s, connection);
  return lost;
}

TEST(SeqGaps, ConsecutiveSeqLosesNothing) {
  SeqGapCounter c;
  EXPECT_EQ(feed(&c, {7, 8, 9, 10, 11}), 0u);
}

TEST(SeqGaps, GapsAfterASteadyStartAreCountedExactly) {
  SeqGapCounter c;
  EXPECT_EQ(feed(&c, {1, 2, 3}), 0u);
  EXPECT_EQ(c.next(7, kDriver), 3u);  // 4, 5, 6
  EXPECT_EQ(c.next(8, kDriver), 0u);
  // Gaps in a row (a queue that keeps overflowing) stay counted.
  EXPECT_EQ(c.next(10, kDriver), 1u);
  EXPECT_EQ(c.next(20, kDriver), 9u);
}

TEST(SeqGaps, SeqAlwaysZeroCountsNothing) {
  SeqGapCounter c;
  for (int i = 0; i < 100; ++i) EXPECT_EQ(c.next(0, kDriver), 0u);
}

TEST(SeqGaps, SeqNeverIncreasingByOneCountsNothing) {
  SeqGapCounter c;
  EXPECT_EQ(feed(&c, {0, 5, 10, 15, 20, 100, 1000}), 0u);
}

TEST(SeqGaps, GoingBackOrStandingStillEndsTrustUntilTheNextStepOfOne) {
  SeqGapCounter c;
  EXPECT_EQ(feed(&c, {1, 2, 3, 4}), 0u);
  // A restarted bag or driver: seq starts again lower; its first forward jump is not a loss.
  EXPECT_EQ(feed(&c, {0, 40}), 0u);
  EXPECT_EQ(feed(&c, {41, 45}), 3u);
  EXPECT_EQ(feed(&c, {45, 50}), 0u);  // a repeated seq ends trust too
}

TEST(SeqGaps, WrapAroundIsAStepOfOne) {
  SeqGapCounter c;
  EXPECT_EQ(feed(&c, {0xfffffffeu, 0xffffffffu, 0u, 1u}), 0u);
  EXPECT_EQ(feed(&c, {0xfffffffeu}), 0u);  // back: untrusted
  EXPECT_EQ(feed(&c, {0xffffffffu, 2u}), 2u);  // 0, 1 lost across the wrap
}

TEST(SeqGaps, HugeForwardJumpIsARestartNotALoss) {
  SeqGapCounter c;
  EXPECT_EQ(feed(&c, {1, 2}), 0u);
  EXPECT_EQ(c.next(2 + SeqGapCounter::kMaxGap + 1, kDriver), 0u);
  EXPECT_EQ(feed(&c, {SeqGapCounter::kMaxGap + 4, SeqGapCounter::kMaxGap + 6}), 1u);
  // The largest gap that still counts.
  SeqGapCounter d;
  EXPECT_EQ(feed(&d, {1, 2}), 0u);
  EXPECT_EQ(d.next(2 + SeqGapCounter::kMaxGap, kDriver), SeqGapCounter::kMaxGap - 1);
}

TEST(SeqGaps, AnotherConnectionStartsAfresh) {
  SeqGapCounter c;
  EXPECT_EQ(feed(&c, {1, 2, 3}, kA), 0u);
  EXPECT_EQ(c.next(500, kB), 0u);  // two drivers on one topic are not a gap
  EXPECT_EQ(c.next(4, kA), 0u);
  EXPECT_EQ(c.next(502, kB), 0u);  // every change of connection starts afresh
  EXPECT_EQ(feed(&c, {503, 505}, kB), 1u);
}

}  // namespace
