// Motion compensation: a still sensor gives back its scan, a moving one is straightened, REP 117
// values survive, full circles wrap.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "wavog_mapping/core/motion_compensation.h"

namespace wavog {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNan = std::numeric_limits<float>::quiet_NaN();

ScanView viewOf(const std::vector<float>& ranges, double angle_min, double inc) {
  ScanView v;
  v.ranges = ranges.data();
  v.count = ranges.size();
  v.angle_min = angle_min;
  v.angle_increment = inc;
  v.range_min = 0.1;
  v.range_max = 80.0;
  return v;
}

/// Range from `pose` along bearing `b` (sensor frame) to the wall x = wall_x (map frame).
float rangeToWallX(const Pose2& pose, double b, double wall_x) {
  const double a = pose.theta + b;
  const double c = std::cos(a);
  if (c <= 1e-9) return kInf;
  const double r = (wall_x - pose.x) / c;
  return r > 0 && r < 80.0 ? static_cast<float>(r) : kInf;
}

TEST(MotionCompensation, InterpolatesAlongTheShorterArc) {
  const Pose2 a{0.0, 0.0, kPi - 0.1}, b{2.0, -2.0, -kPi + 0.1};
  const Pose2 m = interpolate(a, b, 0.5);
  EXPECT_NEAR(m.x, 1.0, 1e-12);
  EXPECT_NEAR(m.y, -1.0, 1e-12);
  EXPECT_NEAR(std::abs(m.theta), kPi, 1e-9);
}

TEST(MotionCompensation, StillSensorReturnsTheSameScan) {
  std::vector<float> ranges;
  for (int i = 0; i < 361; ++i) ranges.push_back(2.0f + 0.01f * static_cast<float>(i % 50));
  ranges[10] = kNan;
  ranges[11] = kInf;
  ranges[12] = -kInf;
  ranges[13] = 0.05f;  // below range_min
  ranges[14] = 80.0f;  // no return (>= range_max)
  const ScanView in = viewOf(ranges, -kPi / 2, kPi / 360);
  const Pose2 pose{3.0, -1.0, 0.7};
  MotionCompensator mc;
  const ScanView out = mc.compensate(in, pose, pose, pose);
  ASSERT_EQ(out.count, in.count);
  EXPECT_EQ(out.angle_min, in.angle_min);
  EXPECT_EQ(out.angle_increment, in.angle_increment);
  EXPECT_EQ(mc.droppedLast(), 0u);
  for (std::size_t i = 0; i < in.count; ++i) {
    if (i >= 10 && i <= 14) continue;
    EXPECT_NEAR(out.ranges[i], in.ranges[i], 1e-5) << i;
  }
  EXPECT_TRUE(std::isnan(out.ranges[10]));
  EXPECT_EQ(out.ranges[11], kInf);
  EXPECT_EQ(out.ranges[12], -kInf);
  EXPECT_EQ(out.ranges[13], 0.05f);
  EXPECT_EQ(out.ranges[14], 80.0f);
}

TEST(MotionCompensation, ForwardMotionIsStraightened) {
  // The sensor drives 1 m towards the wall x = 5 during the sweep (exaggerated to see it).
  const Pose2 start{0.0, 0.0, 0.0}, end{1.0, 0.0, 0.0};
  const double inc = kPi / 360, amin = -kPi / 4;
  std::vector<float> ranges;
  for (int i = 0; i < 181; ++i) {
    const Pose2 p = interpolate(start, end, i / 180.0);
    ranges.push_back(rangeToWallX(p, amin + i * inc, 5.0));
  }
  const Pose2 ref = interpolate(start, end, 0.5);
  MotionCompensator mc;
  const ScanView out = mc.compensate(viewOf(ranges, amin, inc), start, end, ref);
  int hits = 0;
  double worst_raw = 0.0, worst = 0.0;
  for (std::size_t j = 0; j < out.count; ++j) {
    const double b = amin + static_cast<double>(j) * inc;
    worst_raw = std::max(worst_raw, std::abs(ranges[j] * std::cos(b) + ref.x - 5.0));
    if (!std::isfinite(out.ranges[j])) continue;
    ++hits;
    worst = std::max(worst, std::abs(out.ranges[j] * std::cos(b) + ref.x - 5.0));
  }
  EXPECT_GT(hits, 150);
  EXPECT_GT(worst_raw, 0.4);  // uncompensated: the wall bends by up to half the motion
  EXPECT_LT(worst, 0.03);     // compensated: on the wall up to the bin quantisation
}

TEST(MotionCompensation, RotationShiftsBinsAndKeepsNoReturn) {
  // The sensor turns by +10 bins during the sweep; every beam sees a circle of radius 4 except
  // beam 100, which has no return.
  const double inc = 0.01, amin = -1.0;
  std::vector<float> ranges(201, 4.0f);
  ranges[100] = kInf;
  const Pose2 start{0, 0, 0}, end{0, 0, 10 * inc};
  MotionCompensator mc;
  const ScanView out = mc.compensate(viewOf(ranges, amin, inc), start, start /*unused*/, start);
  EXPECT_EQ(out.ranges[100], kInf);
  const ScanView moved = mc.compensate(viewOf(ranges, amin, inc), start, end, start);
  // Beam i was taken at heading 10 * inc * i / 200: it lands in bin i + i / 20.
  EXPECT_EQ(moved.ranges[105], kInf);
  EXPECT_NEAR(moved.ranges[200], 4.0f, 1e-5);
  EXPECT_GT(mc.droppedLast(), 0u);  // the last beams left the field of view
  for (std::size_t j = 0; j < moved.count; ++j) {
    if (std::isfinite(moved.ranges[j])) {
      EXPECT_NEAR(moved.ranges[j], 4.0f, 1e-4);
    }
  }
}

TEST(MotionCompensation, FullCircleWraps) {
  const double inc = 2 * kPi / 360;
  std::vector<float> ranges(360, 3.0f);
  const Pose2 start{0, 0, 0}, end{0, 0, 0.5};
  MotionCompensator mc;
  const ScanView out = mc.compensate(viewOf(ranges, -kPi, inc), start, end, start);
  EXPECT_EQ(mc.droppedLast(), 0u);
  int finite = 0;
  for (std::size_t j = 0; j < out.count; ++j) finite += std::isfinite(out.ranges[j]) ? 1 : 0;
  EXPECT_GT(finite, 320);
}

TEST(MotionCompensation, DegenerateScansPassThrough) {
  std::vector<float> ranges(5, 1.0f);
  MotionCompensator mc;
  const ScanView bad = viewOf(ranges, 0.0, 0.0);
  EXPECT_EQ(mc.compensate(bad, Pose2{}, Pose2{1, 0, 0}, Pose2{}).ranges, ranges.data());
  ScanView empty = viewOf(ranges, 0.0, 0.1);
  empty.count = 0;
  EXPECT_EQ(mc.compensate(empty, Pose2{}, Pose2{1, 0, 0}, Pose2{}).count, 0u);
}

TEST(MotionCompensation, ScanReachFollowsTheLongestReturn) {
  std::vector<float> ranges = {1.0f, 7.5f, kNan, kInf, 90.0f};
  SensorModelParams sensor;
  const ScanView v = viewOf(ranges, 0.0, 0.1);
  EXPECT_NEAR(scanReach(v, sensor, 0.1), 7.5 + 0.2, 1e-9);
  sensor.no_return_clear = 20.0;
  EXPECT_NEAR(scanReach(v, sensor, 0.1), 20.0 + 0.2, 1e-9);
  sensor.max_range = 5.0;  // 7.5 m is now a no-return beam
  sensor.no_return_clear = 0.0;
  EXPECT_NEAR(scanReach(v, sensor, 0.1), 1.0 + 0.2, 1e-9);
  ScanView none = v;
  none.count = 0;
  EXPECT_EQ(scanReach(none, sensor, 0.1), 0.0);
}

}  // namespace
}  // namespace wavog
