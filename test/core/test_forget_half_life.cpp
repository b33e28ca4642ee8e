// Forgetting in seconds (PolicyParams::forget_half_life): each scan forgets by
// g = 1 - 2^(-period / half_life) with its exponent rounded to the map's unit; lazy tags keep the
// product of the scans' factors (pending units), so the tree still equals the dense reference
// with a different gamma per scan; lasers of different rates forget at the same rate per second;
// files keep the units, and files of format version 1 still load.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "dense_reference.h"
#include "test_support.h"
#include "wavog_mapping/core/scan_period.h"

namespace wavog_test {
namespace {

using wavog::MapParams;
using wavog::WaveletMap;

constexpr double kPi = 3.14159265358979323846;
constexpr double kTolerance = 1e-4;  // as the reference equivalence of occupancy

MapParams halfLifeParams(double half_life, bool lazy = true) {
  MapParams p = MapParams::defaultsFor(wavog::PolicyType::kForget);
  p.grid.resolution = 0.1;
  p.grid.block_levels = 6;
  p.policy.forget_half_life = half_life;
  p.lazy_forgetting = lazy;
  return p;
}

TEST(ForgetHalfLife, RateFollowsThePeriodWithinHalfAUnit) {
  const WaveletMap map(halfLifeParams(0.4));
  const double unit = map.forgetUnit();
  ASSERT_GT(unit, 0.0);
  EXPECT_LE(unit, std::ldexp(1.0, -11));  // default pruning: 2^-11 halvings or finer
  for (double period : {0.001, 0.0125, 0.025, 0.1, 0.2, 1.0, 3.0}) {
    const double g = map.forgetRate(period);
    const double halvings = -std::log2(1.0 - g);
    EXPECT_LE(std::fabs(halvings - period / 0.4), unit / 2 + 1e-12) << period;
  }
  // Unknown periods forget by gamma (rounded the same way).
  for (double period : {0.0, -1.0, std::nan(""), HUGE_VAL}) {
    const double g = map.forgetRate(period);
    EXPECT_LE(std::fabs(-std::log2(1.0 - g) + std::log2(1.0 - 0.3)), unit / 2 + 1e-12) << period;
  }
  // Without a half-life every scan forgets by gamma exactly; other policies do not forget.
  EXPECT_EQ(WaveletMap(halfLifeParams(0.0)).forgetRate(0.025), 0.3);
  EXPECT_EQ(WaveletMap(halfLifeParams(0.0)).forgetUnit(), 0.0);
  MapParams clamp = MapParams::defaultsFor(wavog::PolicyType::kClamp);
  clamp.policy.forget_half_life = 0.4;
  EXPECT_EQ(WaveletMap(clamp).forgetRate(0.025), 0.0);
}

TEST(ForgetHalfLife, InvalidHalfLifeIsRefusedNamingIt) {
  for (double h : {-1.0, -1e-9, 2e6, std::nan(""), HUGE_VAL}) {
    MapParams p = halfLifeParams(h);
    const auto errors = p.validate();
    ASSERT_EQ(errors.size(), 1u) << h;
    EXPECT_NE(errors[0].find("forget_half_life"), std::string::npos) << errors[0];
    EXPECT_NE(errors[0].find("[0, 1e6] s"), std::string::npos) << errors[0];
  }
  EXPECT_TRUE(halfLifeParams(0.0).validate().empty());
  EXPECT_TRUE(halfLifeParams(1e6).validate().empty());
  // A half-life far below any scan period forgets everything at each scan.
  EXPECT_GT(WaveletMap(halfLifeParams(1e-9)).forgetRate(0.025), 0.999999);
}

// Random scans, each with a random period (some unknown): the lazy tree, the eager tree and the
// dense reference fed the same per-scan gammas agree cell by cell.
TEST(ForgetHalfLife, LazyTreeEqualsReferenceWithAGammaPerScan) {
  const MapParams lazy_p = halfLifeParams(0.3, true), eager_p = halfLifeParams(0.3, false);
  WaveletMap lazy(lazy_p), eager(eager_p);
  const wavog::CellBox extent{-80, -80, 80, 80};
  DenseReference ref(lazy_p, extent);
  RandomScans scans(424242u, 5.0);
  std::mt19937 rng(7);
  const double periods[] = {0.0125, 0.025, 0.1, 0.2, 0.0, 0.7, 0.0005};
  std::uniform_int_distribution<int> pick(0, 7);
  std::uniform_real_distribution<double> any(0.001, 0.5);
  std::vector<double> gammas;
  for (int i = 0; i < 150; ++i) {
    const OwnedScan s = scans.next();
    wavog::ScanView v = s.view();
    const int k = pick(rng);
    v.period = k < 7 ? periods[k] : any(rng);
    const double g = lazy.forgetRate(v.period);
    gammas.push_back(g);
    ref.setGamma(0, g);
    ref.integrate(s.pose, v);
    lazy.integrate(s.pose, v);
    eager.integrate(s.pose, v);
    if (i % 25 == 24) {
      const Comparison c = compare(lazy, ref);
      EXPECT_LE(c.max_rel_error, kTolerance)
          << "scan " << i << " at " << c.worst_x << ", " << c.worst_y;
      EXPECT_EQ(c.knowledge_mismatches, 0u);
      EXPECT_LE(compare(eager, ref).max_rel_error, kTolerance) << "scan " << i;
    }
  }
  // The scans did forget by different amounts (the test is not the fixed-gamma case again).
  std::sort(gammas.begin(), gammas.end());
  EXPECT_LT(gammas.front(), 0.01);
  EXPECT_GT(gammas.back(), 0.7);
}

// A half-circle scan from the origin whose beams all return at `range` (m).
OwnedScan wallScan(double range) {
  OwnedScan s;
  s.pose = {0.0, 0.0, 0.0};
  s.angle_min = -kPi / 2;
  s.angle_increment = kPi / 180;
  s.range_min = 0.05;
  s.range_max = 30.0;
  s.ranges.assign(181, static_cast<float>(range));
  return s;
}

// The log-odds of the cell 4 m ahead after `seconds_wall` s of a wall there, then
// `seconds_gone` s of the wall at 8 m (the cell free), scanned every `period` s.
double cellAfter(const MapParams& p, double period, double seconds_wall, double seconds_gone) {
  WaveletMap map(p);
  const OwnedScan wall = wallScan(4.0), gone = wallScan(8.0);
  const auto run = [&](const OwnedScan& s, double seconds) {
    const int n = static_cast<int>(std::lround(seconds / period));
    for (int i = 0; i < n; ++i) {
      wavog::ScanView v = s.view();
      v.period = period;
      map.integrate(s.pose, v);
    }
  };
  run(wall, seconds_wall);
  run(gone, seconds_gone);
  return map.value(map.cellAt(4.0 + 0.05, 0.0));
}

TEST(ForgetHalfLife, LasersAt10And40HzForgetACellAtTheSameRatePerSecond) {
  const double h = 0.25;
  const MapParams p = halfLifeParams(h);
  const double occ = p.sensor.odd_occ, emp = p.sensor.odd_emp, range = occ - emp;
  // The closed form: x <- o + (x - o) 2^(-t / h) over each phase, from the prior 0.
  const auto expected = [&](double wall, double gone) {
    const double x1 = occ * (1.0 - std::exp2(-wall / h));
    return emp + (x1 - emp) * std::exp2(-gone / h);
  };
  for (double gone : {0.0, 0.2, 0.5, 1.0}) {
    SCOPED_TRACE(gone);
    const double at10 = cellAfter(p, 0.1, 1.0, gone), at40 = cellAfter(p, 0.025, 1.0, gone);
    // Rounding of each scan's exponent to the unit: well under 1 % of the log-odds range here.
    EXPECT_NEAR(at10, at40, 0.01 * range);
    EXPECT_NEAR(at10, expected(1.0, gone), 0.01 * range);
    EXPECT_NEAR(at40, expected(1.0, gone), 0.01 * range);
  }
  // With gamma per scan (no half-life) the 40 Hz laser forgets four times as fast per second.
  const MapParams per_scan = halfLifeParams(0.0);
  EXPECT_GT(std::fabs(cellAfter(per_scan, 0.1, 1.0, 0.2) - cellAfter(per_scan, 0.025, 1.0, 0.2)),
            0.2 * range);
}

// Issue 28, item 2: half-lives above 2^11 scan periods / 2 made each scan's exponent round to 0
// units (g = 0), so the map stopped learning. Every half-life in the valid range must change it.
TEST(ForgetHalfLife, LongHalfLivesStillLearn) {
  // 500 scans at 10 Hz (50 s) of a wall with a half-life of 1,000 s: the closed form
  // odd_occ (1 - 2^(-50 / 1000)) = 0.119 (the map read 0.0 before).
  const MapParams p = halfLifeParams(1000.0);
  const double expected = p.sensor.odd_occ * (1.0 - std::exp2(-50.0 / 1000.0));
  const double got = cellAfter(p, 0.1, 50.0, 0.0);
  // Each scan's exponent (1e-4 halvings) is rounded to the unit: within 1 / 128 of it.
  EXPECT_NEAR(got, expected, expected / 128) << "half-life 1000 s at 10 Hz";
  // Each scan forgets by its own rate within half a unit, and by at least one unit: never 0.
  for (double h : {409.7, 1000.0, 1e4, 1e5, 1e6}) {
    const WaveletMap map(halfLifeParams(h));
    const double unit = map.forgetUnit();
    for (double period : {1e-9, 0.001, 0.0125, 0.025, 0.1, 1.0}) {
      const double g = map.forgetRate(period);
      EXPECT_GT(g, 0.0) << h << " s, period " << period;
      const double halvings = -std::log2(1.0 - g);
      EXPECT_LE(std::fabs(halvings - period / h), std::max(unit / 2, unit - period / h) * 1.0001)
          << h << " s, period " << period;
    }
    // At 40 Hz the rounding is under 1 % of the exact rate.
    EXPECT_NEAR(map.forgetRate(0.025), 1.0 - std::exp2(-0.025 / h),
                0.01 * (1.0 - std::exp2(-0.025 / h)))
        << h;
  }
  // The longest valid half-life still moves a cell hit at 40 Hz.
  EXPECT_GT(cellAfter(halfLifeParams(1e6), 0.025, 2.0, 0.0), 0.0);
}

// A long half-life has a fine unit: a scan of unknown period (gamma) or of a long one counts more
// units than a tag holds and is applied eagerly, gamma 1 drops the subtree; the tree still equals
// the dense reference fed the map's per-scan rates.
TEST(ForgetHalfLife, FineUnitsEqualReferenceWithLongAndUnknownPeriods) {
  for (double gamma : {0.3, 1.0}) {
    SCOPED_TRACE(gamma);
    MapParams p = halfLifeParams(50.0);
    p.policy.gamma = gamma;
    WaveletMap lazy(p);
    ASSERT_LT(lazy.forgetUnit(), std::ldexp(1.0, -11));  // finer than the tau-based unit
    // Units of a 40 s scan (0.8 halvings) and of gamma 0.3 (0.51) exceed 65535.
    ASSERT_GT(-std::log2(1.0 - lazy.forgetRate(0.0)) / lazy.forgetUnit(), 65535.0);
    const wavog::CellBox extent{-80, -80, 80, 80};
    DenseReference ref(p, extent);
    RandomScans scans(5150u, 5.0);
    const double periods[] = {0.1, 0.0, 40.0, 0.025, 0.1, 1e-7, 0.1};
    for (int i = 0; i < 70; ++i) {
      const OwnedScan s = scans.next();
      wavog::ScanView v = s.view();
      v.period = periods[i % 7];
      ref.setGamma(0, lazy.forgetRate(v.period));
      ref.integrate(s.pose, v);
      lazy.integrate(s.pose, v);
    }
    const Comparison c = compare(lazy, ref);
    EXPECT_LE(c.max_rel_error, kTolerance) << c.worst_x << ", " << c.worst_y;
    EXPECT_EQ(c.knowledge_mismatches, 0u);
  }
}

// Issue 28, item 1: with NDT (or reflection) and a long half-life each end-point added a Gaussian
// of weight 0 (a hit ratio 0 / 0); the map saved, and load() refused it ("bad NDT cell count",
// "non-finite hit ratio").
TEST(ForgetHalfLife, LongHalfLifeMapsWithPayloadsLoadAgain) {
  const std::string path = ::testing::TempDir() + "half_life_payload_" + std::to_string(::getpid());
  for (bool ndt : {true, false}) {
    SCOPED_TRACE(ndt ? "ndt" : "reflection");
    MapParams p = halfLifeParams(1000.0);
    p.ndt = ndt;
    p.ndt_min_weight = 0.0;  // keep the one end-point's Gaussian (weight g = 6.9e-5)
    p.reflection = !ndt;
    WaveletMap map(p);
    const OwnedScan wall = wallScan(4.0);
    wavog::ScanView v = wall.view();
    v.period = 0.1;
    map.integrate(wall.pose, v);  // one scan into new blocks
    map.save(path);
    WaveletMap loaded(p);
    try {
      loaded.load(path);
    } catch (const wavog::MapIoError& e) {
      ADD_FAILURE() << e.what();
      continue;
    }
    expectSameCells(loaded, map, 50, 0.0);
    const wavog::CellIndex c = map.cellAt(4.05, 0.0);
    if (ndt) {
      wavog::NdtCell a, b;
      ASSERT_TRUE(map.ndtCell(c, &a));
      ASSERT_TRUE(loaded.ndtCell(c, &b));
      EXPECT_GT(a.weight, 0.0);
      EXPECT_EQ(a.weight, b.weight);
      EXPECT_EQ(a.mean_x, b.mean_x);
    } else {
      const float r = map.reflection(c);
      EXPECT_TRUE(std::isfinite(r)) << r;
      EXPECT_EQ(r, loaded.reflection(c));
      EXPECT_NEAR(r, 1.0f, 1e-3f);  // hit once, never missed
    }
  }
  std::remove(path.c_str());
}

TEST(ForgetHalfLife, FilesKeepThePendingUnits) {
  const std::string path = ::testing::TempDir() + "half_life_" + std::to_string(::getpid());
  WaveletMap map(halfLifeParams(0.3));
  RandomScans scans(99u, 5.0);
  for (int i = 0; i < 60; ++i) {
    const OwnedScan s = scans.next();
    wavog::ScanView v = s.view();
    v.period = 0.0125 * (1 + i % 8);
    map.integrate(s.pose, v);
  }
  map.save(path);
  // The same parameters: the pending units are kept, the round trip is exact.
  WaveletMap same(halfLifeParams(0.3));
  same.load(path);
  expectSameCells(same, map, 60, 0.0);
  // gamma per scan: one unit means another factor, so the file's tags are applied on loading.
  WaveletMap per_scan(halfLifeParams(0.0));
  per_scan.load(path);
  expectSameCells(per_scan, map, 60, kTolerance);
  std::remove(path.c_str());
}

// test/core/data/forget_v1.wavog was saved by the format-version-1 code (u8 pending counts) from
// the 30 scans of RandomScans(20261201, 6 m) with the "forget" defaults at 0.2 m, block_levels 6.
TEST(ForgetHalfLife, FilesOfFormatVersion1StillLoad) {
  MapParams p = MapParams::defaultsFor(wavog::PolicyType::kForget);
  p.grid.resolution = 0.2;
  p.grid.block_levels = 6;
  WaveletMap made(p);
  RandomScans scans(20261201u, 6.0);
  integrateScans(&scans, 30, made);
  WaveletMap loaded(p);
  loaded.load(std::string(WAVOG_SOURCE_DIR) + "/test/core/data/forget_v1.wavog");
  // Fixed-gamma maps are what they were before forget_half_life, up to the float round-off of the
  // file's details (f32 before version 6; today's maps hold doubles).
  expectSameCells(loaded, made, 40, 1e-6);
  EXPECT_EQ(loaded.stats().nodes, made.stats().nodes);
}

TEST(ScanPeriod, StampDifferencesThenTheDriversScanTimeThenUnknown) {
  constexpr double kEps = 1e-9;
  wavog::ScanPeriod period;
  EXPECT_EQ(period.next(100.0), 0.0);                   // the first scan: unknown
  EXPECT_NEAR(period.next(100.025, 0.5), 0.025, kEps);  // stamps first
  EXPECT_NEAR(period.next(100.125, 0.025), 0.1, kEps);  // a dropped scan is time that passed
  EXPECT_EQ(period.next(105.0, 0.025), 0.025);          // a gap over kMaxPeriod: scan_time
  EXPECT_EQ(period.next(110.0), 0.0);                   // a gap, no scan_time: unknown
  EXPECT_EQ(period.next(109.0), 0.0);                   // backwards: unknown
  EXPECT_NEAR(period.next(109.04), 0.04, kEps);         // on from the backward stamp
  EXPECT_EQ(period.next(std::nan(""), 0.0), 0.0);       // a non-finite stamp
  EXPECT_EQ(period.next(109.1, 5.0), 0.0);              // after it; scan_time too long
  EXPECT_NEAR(period.next(109.2), 0.1, kEps);
}

}  // namespace
}  // namespace wavog_test
