// Unit tests of the dense baseline grid: ray geometry, the once-per-scan and hits-win rules,
// clamping, REP 117 beam handling, growth and stamp wrap-around.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "wavog_mapping/baseline/dense_grid.h"

namespace {

using wavog::CellIndex;
using wavog::Pose2;
using wavog::ScanView;
using wavog::baseline::DenseGrid;
using wavog::baseline::DenseGridParams;

constexpr double kRes = 0.1;
constexpr float kTol = 1.0f / DenseGrid::kScale;

/// A scan of `ranges` with beams spread over [angle_min, angle_min + (n-1) * increment].
struct TestScan {
  std::vector<float> ranges;
  double angle_min = 0.0;
  double angle_increment = 0.01;
  double range_max = 30.0;
  double range_min = 0.05;
  ScanView view() const {
    return ScanView{ranges.data(), ranges.size(), angle_min, angle_increment, range_min, range_max};
  }
};

DenseGridParams testParams() {
  DenseGridParams p;
  p.resolution = kRes;
  p.grow_margin_cells = 4;
  return p;
}

TestScan oneBeam(float range, double angle = 0.0) {
  TestScan s;
  s.ranges = {range};
  s.angle_min = angle;
  return s;
}

TEST(DenseGridParams, DefaultsAreValidAndEveryRuleFails) {
  EXPECT_TRUE(DenseGridParams{}.validate().empty());
  const auto fails = [](DenseGridParams p) { return p.validate().size() == 1; };
  DenseGridParams p;
  p.resolution = 0.0;
  EXPECT_TRUE(fails(p));
  p = {};
  p.hit_log_odds = -0.1;
  EXPECT_TRUE(fails(p));
  p = {};
  p.miss_log_odds = 0.2;
  EXPECT_TRUE(fails(p));
  p = {};
  p.clamp_min_log_odds = -9.0;
  EXPECT_TRUE(fails(p));
  p = {};
  p.clamp_max_log_odds = 0.0;
  EXPECT_TRUE(fails(p));
  p = {};
  p.max_range_m = -1.0;
  EXPECT_TRUE(fails(p));
  p = {};
  p.no_return_clear_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(fails(p));
  p = {};
  p.grow_margin_cells = -1;
  EXPECT_TRUE(fails(p));
  p = {};
  p.resolution = -1.0;
  EXPECT_THROW(DenseGrid{p}, std::invalid_argument);
}

TEST(DenseGrid, OneBeamMarksFreeCellsAndTheEndPoint) {
  DenseGrid grid(testParams());
  const TestScan scan = oneBeam(1.0f);
  const auto stats = grid.integrate(Pose2{0.05, 0.05, 0.0}, scan.view());
  EXPECT_EQ(stats.beams_hit, 1u);
  // Sensor in cell 0, end point at x = 1.05 -> cell 10; cells 0..9 free, 10 occupied.
  for (int x = 0; x < 10; ++x) {
    EXPECT_TRUE(grid.isObserved({x, 0})) << x;
    EXPECT_NEAR(grid.value({x, 0}), -0.4f, kTol) << x;
  }
  EXPECT_NEAR(grid.value({10, 0}), 0.85f, kTol);
  EXPECT_FALSE(grid.isObserved({11, 0}));
  EXPECT_FALSE(grid.isObserved({5, 1}));
  EXPECT_FALSE(grid.isObserved({-1, 0}));
  EXPECT_EQ(stats.cells_updated, 11u);
  EXPECT_EQ(grid.countObserved(), 11u);
  EXPECT_EQ(grid.value({500, 500}), 0.0f);  // outside the grid: the prior
}

TEST(DenseGrid, EachCellUpdatedOncePerScanAndHitsWin) {
  DenseGrid grid(testParams());
  // 50 beams fanning out from one cell: the sensor cell is crossed by all of them.
  TestScan scan;
  scan.angle_min = -0.5;
  scan.angle_increment = 0.02;
  scan.ranges.assign(50, 2.0f);
  grid.integrate(Pose2{0.05, 0.05, 0.0}, scan.view());
  EXPECT_NEAR(grid.value({0, 0}), -0.4f, kTol);

  // A short beam ends in a cell that a longer beam of the same scan crosses: the hit wins, once.
  DenseGrid grid2(testParams());
  TestScan two;
  two.angle_min = 0.0;
  two.angle_increment = 1e-4;
  two.ranges = {3.0f, 1.0f, 3.0f};
  grid2.integrate(Pose2{0.05, 0.05, 0.0}, two.view());
  EXPECT_NEAR(grid2.value({10, 0}), 0.85f, kTol);
  EXPECT_NEAR(grid2.value({5, 0}), -0.4f, kTol);
  EXPECT_NEAR(grid2.value({30, 0}), 0.85f, kTol);
}

TEST(DenseGrid, ClampsAtBothBounds) {
  DenseGrid grid(testParams());
  const TestScan scan = oneBeam(1.0f);
  for (int i = 0; i < 20; ++i) grid.integrate(Pose2{0.05, 0.05, 0.0}, scan.view());
  EXPECT_NEAR(grid.value({3, 0}), -2.0f, kTol);
  EXPECT_NEAR(grid.value({10, 0}), 3.5f, kTol);
  // Three misses from the upper bound: 3.5 - 1.2.
  const TestScan longer = oneBeam(2.0f);
  for (int i = 0; i < 3; ++i) grid.integrate(Pose2{0.05, 0.05, 0.0}, longer.view());
  EXPECT_NEAR(grid.value({10, 0}), 3.5f - 1.2f, 3 * kTol);
}

TEST(DenseGrid, Rep117BeamHandling) {
  DenseGridParams p = testParams();
  p.no_return_clear_m = 1.0;
  DenseGrid grid(p);
  TestScan scan;
  scan.angle_min = 0.0;
  scan.angle_increment = M_PI / 2;  // beams along +x, +y, -x, -y
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  scan.ranges = {inf, nan, 0.01f /* < range_min */, 35.0f /* >= range_max */};
  const auto stats = grid.integrate(Pose2{0.05, 0.05, 0.0}, scan.view());
  EXPECT_EQ(stats.beams_hit, 0u);
  EXPECT_EQ(stats.beams_no_return, 2u);
  EXPECT_EQ(stats.beams_invalid, 2u);
  // +inf clears [0, 1 m) along +x with no hit; 35 m clears along -y; NaN and 0.01 do nothing.
  EXPECT_NEAR(grid.value({9, 0}), -0.4f, kTol);
  EXPECT_FALSE(grid.isObserved({10, 0}));
  EXPECT_FALSE(grid.isObserved({0, 3}));
  EXPECT_FALSE(grid.isObserved({-3, 0}));
  EXPECT_NEAR(grid.value({0, -5}), -0.4f, kTol);

  DenseGrid no_clear(testParams());
  no_clear.integrate(Pose2{0.05, 0.05, 0.0}, scan.view());
  EXPECT_EQ(no_clear.countObserved(), 0u);

  // max_range_m overrides the scan's range_max.
  DenseGridParams short_range = testParams();
  short_range.max_range_m = 0.5;
  DenseGrid limited(short_range);
  const auto s2 = limited.integrate(Pose2{0.05, 0.05, 0.0}, oneBeam(1.0f).view());
  EXPECT_EQ(s2.beams_no_return, 1u);
  EXPECT_EQ(limited.countObserved(), 0u);
}

TEST(DenseGrid, RejectsBadPoseAndGeometry) {
  DenseGrid grid(testParams());
  TestScan scan = oneBeam(1.0f);
  EXPECT_TRUE(grid.integrate(Pose2{std::nan(""), 0.0, 0.0}, scan.view()).rejected);
  scan.angle_increment = 0.0;
  EXPECT_TRUE(grid.integrate(Pose2{}, scan.view()).rejected);
  EXPECT_EQ(grid.countObserved(), 0u);
  EXPECT_TRUE(grid.extent().empty());
}

/// True if the segment a-b (cell units) meets the closed unit square of cell (cx, cy), widened by
/// `eps` (Liang-Barsky clipping).
bool segmentMeetsCell(double ax, double ay, double bx, double by, std::int64_t cx, std::int64_t cy,
                      double eps) {
  double t0 = 0.0, t1 = 1.0;
  const double d[2] = {bx - ax, by - ay};
  const double a[2] = {ax, ay};
  const double lo[2] = {static_cast<double>(cx) - eps, static_cast<double>(cy) - eps};
  const double hi[2] = {static_cast<double>(cx) + 1 + eps, static_cast<double>(cy) + 1 + eps};
  for (int k = 0; k < 2; ++k) {
    if (d[k] == 0.0) {
      if (a[k] < lo[k] || a[k] > hi[k]) return false;
      continue;
    }
    double ta = (lo[k] - a[k]) / d[k];
    double tb = (hi[k] - a[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

TEST(DenseGrid, IntegerDdaVisitsExactlyTheCellsTheSegmentCrosses) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> pos(-3.0, 3.0);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  std::uniform_real_distribution<double> range(0.05, 8.0);
  for (int trial = 0; trial < 300; ++trial) {
    DenseGrid grid(testParams());
    const Pose2 pose{pos(rng), pos(rng), angle(rng)};
    const double r = range(rng);
    const TestScan scan = oneBeam(static_cast<float>(r));
    grid.integrate(pose, scan.view());
    const double ax = pose.x / kRes, ay = pose.y / kRes;
    const double bx = ax + r / kRes * std::cos(pose.theta);
    const double by = ay + r / kRes * std::sin(pose.theta);
    const CellIndex end =
        grid.cellAt(pose.x + r * std::cos(pose.theta), pose.y + r * std::sin(pose.theta));
    const CellIndex start = grid.cellAt(pose.x, pose.y);
    const wavog::CellBox box = grid.extent();
    std::uint64_t free_cells = 0;
    for (std::int64_t y = box.min_y; y < box.max_y; ++y) {
      for (std::int64_t x = box.min_x; x < box.max_x; ++x) {
        if (!grid.isObserved({x, y})) {
          // A cell the segment crosses well inside must have been visited.
          EXPECT_FALSE(segmentMeetsCell(ax, ay, bx, by, x, y, -1e-3))
              << "missed cell " << x << "," << y << " trial " << trial;
          continue;
        }
        if (x == end.x && y == end.y) {
          EXPECT_NEAR(grid.value({x, y}), 0.85f, kTol);
          continue;
        }
        ++free_cells;
        EXPECT_NEAR(grid.value({x, y}), -0.4f, kTol);
        EXPECT_TRUE(segmentMeetsCell(ax, ay, bx, by, x, y, 1e-3))
            << "cell " << x << "," << y << " off the ray, trial " << trial;
      }
    }
    // A 4-connected traversal from the start cell to the end cell visits |dx| + |dy| cells before
    // the end cell.
    const std::uint64_t expected =
        static_cast<std::uint64_t>(std::abs(end.x - start.x) + std::abs(end.y - start.y));
    EXPECT_EQ(free_cells, expected) << "trial " << trial;
  }
}

TEST(DenseGrid, GrowsInEveryDirectionAndKeepsContents) {
  DenseGrid grid(testParams());
  const TestScan scan = oneBeam(1.0f);
  grid.integrate(Pose2{0.05, 0.05, 0.0}, scan.view());
  const float before = grid.value({5, 0});
  grid.integrate(Pose2{-49.95, 30.05, M_PI}, scan.view());
  grid.integrate(Pose2{40.05, -59.95, -M_PI / 2}, scan.view());
  EXPECT_EQ(grid.value({5, 0}), before);
  EXPECT_NEAR(grid.value(grid.cellAt(-50.95, 30.05)), 0.85f, kTol);
  EXPECT_NEAR(grid.value(grid.cellAt(40.05, -60.95)), 0.85f, kTol);
  EXPECT_EQ(grid.countObserved(), 33u);
  const wavog::CellBox box = grid.extent();
  EXPECT_LE(box.min_x, -510);
  EXPECT_LE(box.min_y, -610);
  EXPECT_GE(box.max_x, 401);
  EXPECT_GE(box.max_y, 301);
  EXPECT_GE(grid.bytes(), static_cast<std::size_t>(box.width() * box.height() * 4));
}

TEST(DenseGrid, ReserveCoversTheBoxAndScansInsideDoNotGrow) {
  DenseGrid grid(testParams());
  grid.reserve(wavog::CellBox{-100, -50, 200, 80});
  const wavog::CellBox before = grid.extent();
  EXPECT_LE(before.min_x, -100);
  EXPECT_LE(before.min_y, -50);
  EXPECT_GE(before.max_x, 200);
  EXPECT_GE(before.max_y, 80);
  EXPECT_EQ(grid.countObserved(), 0u);
  grid.integrate(Pose2{0.05, 0.05, 0.0}, oneBeam(5.0f).view());
  const wavog::CellBox after = grid.extent();
  EXPECT_EQ(after.min_x, before.min_x);
  EXPECT_EQ(after.max_x, before.max_x);
  EXPECT_EQ(after.min_y, before.min_y);
  EXPECT_EQ(after.max_y, before.max_y);
  EXPECT_NEAR(grid.value({50, 0}), 0.85f, kTol);
  grid.reserve(wavog::CellBox{});  // empty: nothing happens
  EXPECT_EQ(grid.extent().min_x, before.min_x);
}

TEST(DenseGrid, StampWrapAroundKeepsOncePerScan) {
  DenseGrid grid(testParams());
  const TestScan far_beam = oneBeam(0.5f);
  // 65534 scans elsewhere bring the 16-bit stamp to the edge of its wrap-around.
  for (int i = 0; i < 65534; ++i) grid.integrate(Pose2{-10.0, -10.0, 0.0}, far_beam.view());
  TestScan fan;
  fan.angle_min = -0.3;
  fan.angle_increment = 0.05;
  fan.ranges.assign(13, 1.0f);
  for (int i = 0; i < 3; ++i) grid.integrate(Pose2{5.05, 5.05, 0.0}, fan.view());
  // Every scan crossed the sensor cell 13 times, and updated it once.
  EXPECT_NEAR(grid.value(grid.cellAt(5.05, 5.05)), -1.2f, 3 * kTol);
}

}  // namespace
