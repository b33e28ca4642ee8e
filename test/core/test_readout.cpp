// Read-out, knowledge, region operations and scan validation.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "dense_reference.h"
#include "test_support.h"

namespace wavog_test {
namespace {

using wavog::Aggregation;
using wavog::CellBox;
using wavog::MapParams;
using wavog::ScanStatus;
using wavog::WaveletMap;

constexpr double kPi = 3.14159265358979323846;

OwnedScan wallScan(double range = 3.0) {
  OwnedScan s;
  s.pose = {0.02, 0.03, 0.0};
  s.angle_min = -kPi / 2;
  s.angle_increment = kPi / 180;
  s.range_min = 0.1;
  s.range_max = 10.0;
  s.ranges.assign(181, static_cast<float>(range));
  return s;
}

MapParams params(wavog::PolicyType t = wavog::PolicyType::kForget) {
  MapParams p = MapParams::defaultsFor(t);
  p.grid.resolution = 0.1;
  p.grid.block_levels = 5;
  return p;
}

TEST(Readout, OccupancyValues) {
  EXPECT_EQ(wavog::occupancyFromLogOdds(0.0f), 50);
  EXPECT_EQ(wavog::occupancyFromLogOdds(-20.0f), 0);
  EXPECT_EQ(wavog::occupancyFromLogOdds(20.0f), 100);
  EXPECT_EQ(wavog::occupancyFromLogOdds(std::log(3.0f)), 75);
  wavog::Raster r;
  r.log_odds = {0.0f, 5.0f, -5.0f};
  r.known = {0, 1, 1};
  const auto g = wavog::toOccupancyGrid(r);
  EXPECT_EQ(g[0], -1);
  EXPECT_EQ(g[1], 99);
  EXPECT_EQ(g[2], 1);
}

// The trinary values (map_server's rule): above occupied_thresh 100, below free_thresh 0,
// between and never observed -1; graded values are the same as toOccupancyGrid(raster).
TEST(Readout, TrinaryValuesFollowTheThresholds) {
  const auto logit = [](double p) { return static_cast<float>(std::log(p / (1.0 - p))); };
  wavog::Raster r;
  r.log_odds = {0.0f, logit(0.66), logit(0.64), logit(0.20), logit(0.19), 20.0f, -20.0f, 5.0f};
  r.known = {1, 1, 1, 1, 1, 1, 1, 0};
  const wavog::GridValues trinary;  // 0.65 / 0.196
  const std::vector<std::int8_t> expect = {-1, 100, -1, -1, 0, 100, 0, -1};
  EXPECT_EQ(wavog::toOccupancyGrid(r, trinary), expect);
  wavog::GridValues strict;
  strict.occupied_thresh = 0.9;
  strict.free_thresh = 0.1;
  EXPECT_EQ(wavog::toOccupancyGrid(r, strict),
            (std::vector<std::int8_t>{-1, -1, -1, -1, -1, 100, 0, -1}));
  wavog::GridValues graded;
  graded.trinary = false;
  EXPECT_EQ(wavog::toOccupancyGrid(r, graded), wavog::toOccupancyGrid(r));
  EXPECT_EQ(wavog::gridValue(std::numeric_limits<float>::quiet_NaN(), true, trinary), -1);
}

TEST(Readout, HitBeatsMissInOneScanAndUnknownStaysUnknown) {
  WaveletMap map(params());
  const auto s = wallScan();
  const auto st = map.integrate(s.pose, s.view());
  ASSERT_EQ(st.status, ScanStatus::kOk);
  EXPECT_EQ(st.beams_hit, 181u);
  // The hit straight ahead at x = 3.02.
  const auto hit = map.cellAt(3.02, 0.03);
  EXPECT_TRUE(map.isObserved(hit));
  EXPECT_GT(map.value(hit), 0.5f);
  const auto free_cell = map.cellAt(1.5, 0.0);
  EXPECT_TRUE(map.isObserved(free_cell));
  EXPECT_LT(map.value(free_cell), -0.5f);
  // Behind the sensor and behind the wall: never observed, at the prior, at every scale.
  for (auto c : {map.cellAt(-1.0, 0.0), map.cellAt(4.0, 0.0)}) {
    EXPECT_FALSE(map.isObserved(c));
    EXPECT_EQ(map.value(c), 0.0f);
  }
  for (int scale = 0; scale <= 3; ++scale) {
    const CellBox box = map.boxAround(-5, -5, 5, 5, scale);
    const auto r = map.exportScale(scale, box, Aggregation::kMax);
    const auto g = wavog::toOccupancyGrid(r);
    const double cell = r.cell_size;
    auto at = [&](double x, double y) {
      const auto ix = static_cast<std::int64_t>(std::floor(x / cell)) - box.min_x;
      const auto iy = static_cast<std::int64_t>(std::floor(y / cell)) - box.min_y;
      return g[static_cast<std::size_t>(iy * box.width() + ix)];
    };
    EXPECT_EQ(at(-4.5, -4.5), -1) << "scale " << scale;
    EXPECT_GT(at(3.02, 0.03), 50) << "scale " << scale;  // max keeps the wall at every scale
  }
}

TEST(Readout, RasterGeometry) {
  WaveletMap map(params());
  const auto s = wallScan();
  map.integrate(s.pose, s.view());
  CellBox b;
  ASSERT_TRUE(map.bounds(2, &b));
  const auto r = map.exportScale(2, b, Aggregation::kMean);
  EXPECT_DOUBLE_EQ(r.cell_size, 0.4);
  EXPECT_DOUBLE_EQ(r.originX(), static_cast<double>(b.min_x) * 0.4);
  EXPECT_EQ(r.log_odds.size(), static_cast<std::size_t>(b.width() * b.height()));
  // Window not aligned to blocks, partly outside the map.
  const CellBox w{-3, -2, 17, 9};
  const auto part = map.exportScale(0, w, Aggregation::kMean);
  for (std::int64_t y = w.min_y; y < w.max_y; ++y)
    for (std::int64_t x = w.min_x; x < w.max_x; ++x) {
      const auto i = static_cast<std::size_t>((y - w.min_y) * w.width() + (x - w.min_x));
      EXPECT_FLOAT_EQ(part.log_odds[i], map.value({x, y}));
      EXPECT_EQ(part.known[i] != 0, map.isObserved({x, y}));
    }
  WaveletMap empty(params());
  EXPECT_FALSE(empty.bounds(0, &b));
}

TEST(Readout, ClearBoxOnlyClearsTheBox) {
  for (auto t : {wavog::PolicyType::kForget, wavog::PolicyType::kClamp}) {
    WaveletMap map(params(t));
    for (int i = 0; i < 3; ++i) {
      auto s = wallScan(3.0 + 0.05 * i);
      map.integrate(s.pose, s.view());
    }
    CellBox b;
    ASSERT_TRUE(map.bounds(0, &b));
    std::vector<float> before;
    std::vector<bool> obs;
    for (std::int64_t y = b.min_y; y < b.max_y; ++y)
      for (std::int64_t x = b.min_x; x < b.max_x; ++x) {
        before.push_back(map.value({x, y}));
        obs.push_back(map.isObserved({x, y}));
      }
    map.clearBox(1.0, -1.0, 3.3, 0.5);
    std::size_t k = 0, cleared = 0;
    for (std::int64_t y = b.min_y; y < b.max_y; ++y)
      for (std::int64_t x = b.min_x; x < b.max_x; ++x, ++k) {
        const double cx = (x + 0.5) * 0.1, cy = (y + 0.5) * 0.1;
        const bool inside = cx >= 1.0 && cx <= 3.3 && cy >= -1.0 && cy <= 0.5;
        if (inside) {
          EXPECT_FALSE(map.isObserved({x, y}));
          EXPECT_NEAR(map.value({x, y}), 0.0f, 1e-6);
          cleared += obs[k] ? 1 : 0;
        } else {
          EXPECT_NEAR(map.value({x, y}), before[k], 1e-5);
          EXPECT_EQ(map.isObserved({x, y}), obs[k]);
        }
      }
    EXPECT_GT(cleared, 100u);
    map.reset();
    EXPECT_EQ(map.stats().blocks, 0u);
    EXPECT_EQ(map.stats().nodes, 0u);
    EXPECT_FALSE(map.isObserved(map.cellAt(2.0, 0.0)));
  }
}

TEST(Readout, BadScansAreRefusedAndChangeNothing) {
  WaveletMap map(params());
  auto s = wallScan();
  auto v = s.view();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  struct Case {
    const char* what;
    wavog::ScanView view;
    wavog::Pose2 pose;
    ScanStatus want;
  };
  std::vector<Case> cases;
  auto bad = v;
  bad.count = 0;
  cases.push_back({"empty", bad, s.pose, ScanStatus::kEmpty});
  bad = v;
  bad.angle_increment = 0;
  cases.push_back({"zero increment", bad, s.pose, ScanStatus::kBadGeometry});
  bad = v;
  bad.angle_increment = nan;
  cases.push_back({"nan increment", bad, s.pose, ScanStatus::kBadGeometry});
  bad = v;
  bad.angle_increment = 0.1;  // 181 beams over 18 rad
  cases.push_back({"fov > 2 pi", bad, s.pose, ScanStatus::kBadGeometry});
  bad = v;
  bad.range_max = 0.05;
  cases.push_back({"range_max < range_min", bad, s.pose, ScanStatus::kBadGeometry});
  cases.push_back({"nan pose", v, {nan, 0, 0}, ScanStatus::kBadPose});
  std::vector<float> all_nan(181, nan);
  bad = v;
  bad.ranges = all_nan.data();
  cases.push_back({"all nan", bad, s.pose, ScanStatus::kNoValidBeam});
  for (const auto& c : cases) {
    const auto st = map.integrate(c.pose, c.view);
    EXPECT_EQ(st.status, c.want) << c.what;
    EXPECT_EQ(map.stats().blocks, 0u) << c.what;
  }
  EXPECT_STREQ(wavog::toString(ScanStatus::kBadGeometry), "bad_geometry");
}

TEST(Readout, NoReturnClearsOnlyWhenConfigured) {
  auto s = wallScan();
  std::fill(s.ranges.begin(), s.ranges.end(), std::numeric_limits<float>::infinity());
  MapParams p = params();
  WaveletMap off(p);
  const auto st = off.integrate(s.pose, s.view());
  EXPECT_EQ(st.beams_no_return, 181u);
  EXPECT_EQ(st.status, ScanStatus::kNoValidBeam);
  EXPECT_FALSE(off.isObserved(off.cellAt(1.0, 0.0)));
  p.sensor.no_return_clear = 2.0;
  WaveletMap on(p);
  EXPECT_EQ(on.integrate(s.pose, s.view()).status, ScanStatus::kOk);
  EXPECT_TRUE(on.isObserved(on.cellAt(1.0, 0.0)));
  EXPECT_LT(on.value(on.cellAt(1.0, 0.0)), 0.0f);
  EXPECT_FALSE(on.isObserved(on.cellAt(2.5, 0.0)));  // beyond the clearing distance
  // Never a hit: no cell became occupied.
  const auto r = on.exportScale(0, on.boxAround(-3, -3, 3, 3, 0), Aggregation::kMax);
  for (std::size_t i = 0; i < r.log_odds.size(); ++i) {
    if (r.known[i]) {
      EXPECT_LT(r.log_odds[i], 0.0f);
    }
  }
}

TEST(Readout, GrowsInEveryDirection) {
  WaveletMap map(params());
  for (double x : {-1000.0, 1000.0}) {
    for (double y : {-1000.0, 1000.0}) {
      auto s = wallScan();
      s.pose = {x, y, 0.0};
      map.integrate(s.pose, s.view());
      EXPECT_GT(map.value(map.cellAt(x + 3.0, y)), 0.5f) << x << "," << y;
    }
  }
  const auto st = map.stats(true);
  EXPECT_GT(st.observed_cells, 4u * 1000u);
  EXPECT_GT(st.bytes, 0u);
  EXPECT_GE(st.bytes_reserved, st.bytes);
}

}  // namespace
}  // namespace wavog_test
