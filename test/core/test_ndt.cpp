// Normal-distribution cells (MapParams::ndt): against the dense reference, which keeps map-frame
// moment sums per cell and forgets, caps and drops them cell by cell (dense_reference.cpp), for
// every policy and prior, on random scans with every bad beam kind and on the first 500 fr079
// scans, at every scale (coarse Gaussians merged from map-frame sums, the tree's from cell-local
// moments shifted to the coarse centre); forgetting with per-scan rates; files, clearing, the
// thread count; off by default.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "dense_reference.h"
#include "test_support.h"

namespace wavog_test {
namespace {

using wavog::CellBox;
using wavog::MapParams;
using wavog::NdtCell;
using wavog::PolicyType;
using wavog::WaveletMap;

constexpr double kRelative = 1e-4;

MapParams ndtParams(PolicyType type, double res, int levels) {
  MapParams p = MapParams::defaultsFor(type);
  p.grid.resolution = res;
  p.grid.block_levels = levels;
  p.ndt = true;
  p.ndt_max_weight = 3.0;  // reached by the random scans' repeated hits
  return p;
}

// |a - b| within kRelative of b, or of `floor` for values near 0.
bool near(double a, double b, double floor) {
  return std::fabs(a - b) <= kRelative * std::max(std::fabs(b), floor);
}

// Every scale: the tree's Gaussians are the reference's, cell for cell. `finest`: the
// Gaussians at scale 0.
void expectSameNdt(const WaveletMap& map, const DenseReference& ref, int max_scale,
                   const std::string& what, std::size_t* finest = nullptr) {
  const CellBox& e = ref.extent();
  const double res = map.resolution();
  for (int s = 0; s <= max_scale; ++s) {
    const CellBox box{-((-e.min_x) >> s), -((-e.min_y) >> s), e.max_x >> s, e.max_y >> s};
    const wavog::NdtLayer got = map.exportNdt(s, box);
    const std::vector<NdtCell> want = ref.ndtLayer(s, box);
    ASSERT_EQ(got.cells.size(), want.size()) << what << " scale " << s;
    ASSERT_GT(want.size(), 0u) << what << " scale " << s;
    const double cell = res * std::ldexp(1.0, s);
    std::size_t bad = 0;
    for (std::size_t i = 0; i < want.size(); ++i) {
      const NdtCell& g = got.cells[i];
      const NdtCell& w = want[i];
      const bool same = g.ix == w.ix && g.iy == w.iy && near(g.weight, w.weight, 1e-6) &&
                        std::fabs(g.mean_x - w.mean_x) <= kRelative * cell &&
                        std::fabs(g.mean_y - w.mean_y) <= kRelative * cell &&
                        near(g.cov_xx, w.cov_xx, 1e-6 * cell * cell) &&
                        near(g.cov_xy, w.cov_xy, 1e-6 * cell * cell) &&
                        near(g.cov_yy, w.cov_yy, 1e-6 * cell * cell);
      if (!same && bad++ < 3) {
        ADD_FAILURE() << what << " scale " << s << " cell (" << w.ix << ", " << w.iy << "): weight "
                      << g.weight << " vs " << w.weight << ", mean (" << g.mean_x << ", "
                      << g.mean_y << ") vs (" << w.mean_x << ", " << w.mean_y << "), cov ("
                      << g.cov_xx << ", " << g.cov_xy << ", " << g.cov_yy << ") vs (" << w.cov_xx
                      << ", " << w.cov_xy << ", " << w.cov_yy << ")";
      }
      // The mean lies in its cell; the occupancy is the cell's Haar average.
      EXPECT_GE(g.mean_x, static_cast<double>(g.ix) * cell - 1e-9);
      EXPECT_LE(g.mean_x, static_cast<double>(g.ix + 1) * cell + 1e-9);
      if (s == 0) {
        EXPECT_EQ(g.log_odds, map.value({g.ix, g.iy}));
        NdtCell point;
        ASSERT_TRUE(map.ndtCell({g.ix, g.iy}, &point));
        EXPECT_EQ(point.weight, g.weight);
        EXPECT_EQ(point.mean_x, g.mean_x);
      }
    }
    EXPECT_EQ(bad, 0u) << what << " scale " << s;
    if (s == 0 && finest != nullptr) *finest = want.size();
  }
}

TEST(Ndt, RandomScansEveryPolicyAndPriorEveryScale) {
  const double res = 0.1, half = 12.0;
  const auto cells = static_cast<std::int64_t>(std::ceil(half / res));
  for (int levels : {3, 5}) {
    for (PolicyType type : everyPolicyType()) {
      for (wavog::InitValue init : {wavog::InitValue::kUnknown, wavog::InitValue::kEmptyBound}) {
        const std::string name = std::string(wavog::toString(type)) + " " + wavog::toString(init) +
                                 " L" + std::to_string(levels);
        SCOPED_TRACE(name);
        MapParams p = ndtParams(type, res, levels);
        p.policy.init = init;
        WaveletMap map(p);
        DenseReference ref(p, CellBox{-cells, -cells, cells, cells});
        RandomScans scans(4242u + static_cast<unsigned>(levels), half);
        integrateScans(&scans, 200, map, ref);
        expectSameNdt(map, ref, levels, name);
        EXPECT_EQ(map.stats().ndt_cells, ref.ndtCells());
      }
    }
  }
}

TEST(Ndt, RealDataFr079First500ScansEveryPolicy) {
  const std::vector<OwnedScan> log = fr079Scans(500);
  ASSERT_EQ(log.size(), 500u);
  const CellBox extent{-600, -600, 600, 600};
  for (PolicyType type : everyPolicyType()) {
    SCOPED_TRACE(wavog::toString(type));
    MapParams p = ndtParams(type, 0.1, 6);
    p.ndt_max_weight = 20.0;
    WaveletMap map(p);
    DenseReference ref(p, extent);
    for (const OwnedScan& s : log) {
      map.integrate(s.pose, s.view());
      ref.integrate(s.pose, s.view());
    }
    std::size_t finest = 0;
    expectSameNdt(map, ref, 6, wavog::toString(type), &finest);
    EXPECT_GT(finest, 1000u);
  }
}

// forget_half_life: each scan forgets by its own rate; the reference takes the rate the map
// reports for the scan's period.
TEST(Ndt, ForgettingWithPerScanRates) {
  MapParams p = ndtParams(PolicyType::kForget, 0.1, 5);
  p.policy.forget_half_life = 0.4;
  WaveletMap map(p);
  DenseReference ref(p, CellBox{-120, -120, 120, 120});
  RandomScans scans(99u, 12.0);
  const double periods[] = {0.025, 0.1, 0.0, 0.3, 0.05};
  for (int i = 0; i < 150; ++i) {
    const OwnedScan s = scans.next();
    wavog::ScanView v = s.view();
    v.period = periods[i % 5];
    ref.setGamma(0, map.forgetRate(v.period));
    map.integrate(s.pose, v);
    ref.integrate(s.pose, v);
  }
  expectSameNdt(map, ref, 5, "forget_half_life");
}

// Pruning, the skip of unchanged free squares (ALGORITHM.md 3.4) and eager forgetting change how
// the tree walks, not which Gaussians the scan observes: they stay exact.
TEST(Ndt, ExactUnderPruningSkipsAndEagerForgetting) {
  for (int variant = 0; variant < 2; ++variant) {
    MapParams p = ndtParams(PolicyType::kForget, 0.1, 5);
    if (variant == 0) {
      p.prune_threshold = 0.05;
      p.skip_tolerance = 0.01;
    } else {
      p.lazy_forgetting = false;
    }
    WaveletMap map(p);
    DenseReference ref(p, CellBox{-120, -120, 120, 120});
    RandomScans scans(7u + static_cast<unsigned>(variant), 12.0);
    integrateScans(&scans, 200, map, ref);
    expectSameNdt(map, ref, 5, variant == 0 ? "pruned, skipping" : "eager");
  }
}

// A wall seen from afar: the Gaussians of its cells lie on it, thin across it; once the wall is
// gone (the beams pass through), forgetting drops them.
TEST(Ndt, WallGaussiansAndTheirForgetting) {
  MapParams p = ndtParams(PolicyType::kForget, 0.1, 6);
  WaveletMap map(p);
  // A wall at x = 3.03 m seen by 181 beams over +-30 deg from the origin.
  const int n = 181;
  const double amin = -M_PI / 6, inc = (M_PI / 3) / (n - 1);
  std::vector<float> wall(n), gone(n, 20.0f);
  for (int j = 0; j < n; ++j)
    wall[static_cast<std::size_t>(j)] = static_cast<float>(3.03 / std::cos(amin + inc * j));
  OwnedScan s;
  s.pose = {0.0, 0.0, 0.0};
  s.angle_min = amin;
  s.angle_increment = inc;
  s.range_min = 0.1;
  s.range_max = 10.0;
  s.ranges = wall;
  for (int i = 0; i < 10; ++i) map.integrate(s.pose, s.view());
  const wavog::NdtLayer layer = map.exportNdt(0, CellBox{-100, -100, 100, 100});
  ASSERT_GT(layer.cells.size(), 10u);
  for (const NdtCell& c : layer.cells) {
    EXPECT_NEAR(c.mean_x, 3.03, 1e-4);
    EXPECT_LT(c.cov_xx, 1e-8);  // all points at x = 3.03
    EXPECT_GT(c.cov_yy, 0.0);   // spread along the wall
    EXPECT_GT(c.log_odds, 0.0f);
  }
  // The wall is gone: the beams end at a wall 8 m away, every former wall cell is now E.
  const auto near_wall = [&map] {
    std::size_t count = 0;
    for (const NdtCell& c : map.exportNdt(0, CellBox{-100, -100, 100, 100}).cells) {
      count += c.mean_x < 5.0 ? 1 : 0;
    }
    return count;
  };
  for (int j = 0; j < n; ++j)
    gone[static_cast<std::size_t>(j)] = static_cast<float>(8.0 / std::cos(amin + inc * j));
  s.ranges = gone;
  map.integrate(s.pose, s.view());
  EXPECT_EQ(near_wall(), layer.cells.size()) << "one observation forgets, it does not drop";
  for (int i = 0; i < 40; ++i) map.integrate(s.pose, s.view());
  EXPECT_EQ(near_wall(), 0u) << "forgotten Gaussians drop under ndt_min_weight";
  EXPECT_GT(map.stats().ndt_cells, 10u) << "the far wall's";
}

// A straight wall at x m seen from the origin by 31 beams 2 deg apart (over +-30 deg): at most one
// end-point per 0.1 m cell and scan at 3.03 m.
OwnedScan straightWall(double x) {
  OwnedScan s;
  s.pose = {0.0, 0.0, 0.0};
  s.angle_min = -M_PI / 6;
  s.angle_increment = M_PI / 90;
  s.range_min = 0.1;
  s.range_max = 10.0;
  for (int j = 0; j < 31; ++j) {
    s.ranges.push_back(static_cast<float>(x / std::cos(s.angle_min + j * s.angle_increment)));
  }
  return s;
}

// Issue 38: under forgetting a new end-point weighs the scan's rate g (0.3 by gamma, 6.9e-5 with
// a half-life of 1000 s at 10 Hz) and ndt_min_weight counts end-points, so a wall seen every
// scan keeps every Gaussian at every half-life and rate: 300 scans give each wall cell the
// weight 1 - (1 - g)^300, the same Gaussians as with no floor at all.
TEST(Ndt, WallSeenEveryScanKeepsItsGaussianAtEveryHalfLifeAndRate) {
  const OwnedScan wall = straightWall(3.03);
  for (double rate : {10.0, 40.0}) {
    for (double half_life : {0.0, 5.0, 7.0, 10.0, 100.0, 1000.0, 1e6}) {
      const std::string what =
          "half-life " + std::to_string(half_life) + " s at " + std::to_string(rate) + " Hz";
      SCOPED_TRACE(what);
      MapParams p = ndtParams(PolicyType::kForget, 0.1, 6);
      p.policy.forget_half_life = half_life;
      ASSERT_EQ(p.ndt_min_weight, 0.01);  // the default
      MapParams no_floor = p;
      no_floor.ndt_min_weight = 0.0;
      WaveletMap map(p), all(no_floor);
      wavog::ScanView v = wall.view();
      v.period = 1.0 / rate;
      for (int i = 0; i < 300; ++i) {
        map.integrate(wall.pose, v);
        all.integrate(wall.pose, v);
      }
      const double g = map.forgetRate(v.period);
      EXPECT_EQ(map.stats().ndt_cells, all.stats().ndt_cells);
      EXPECT_GE(all.stats().ndt_cells, 31u);
      NdtCell c;  // the cell of the beam at 2 deg
      if (!map.ndtCell(map.cellAt(3.03, 3.03 * std::tan(M_PI / 90)), &c)) {
        ADD_FAILURE() << "the wall's Gaussian is gone, g " << g;
        continue;
      }
      EXPECT_NEAR(c.weight, 1.0 - std::pow(1.0 - g, 300), 1e-9 * c.weight + 1e-15);
      EXPECT_NEAR(c.mean_x, 3.03, 1e-6);
    }
  }
}

// ndt_min_weight in end-points under forgetting: a Gaussian of one end-point, observed from then
// on without another, lasts as long as (1 - g)^k >= ndt_min_weight, log2(1 / 0.01) = 6.6
// half-lives of observation by default, whatever the half-life and the rate (13 scans by gamma
// 0.3). A wall seen every scan holds 1 / g end-points' worth and lasts log2(1 / (0.01 g)).
TEST(Ndt, OneEndPointLastsMinWeightOfItsWorthAtEveryRate) {
  const OwnedScan wall = straightWall(3.03), gone = straightWall(8.0);
  for (double rate : {10.0, 40.0}) {
    for (double half_life : {0.0, 5.0}) {
      SCOPED_TRACE("half-life " + std::to_string(half_life) + " s at " + std::to_string(rate));
      MapParams p = ndtParams(PolicyType::kForget, 0.1, 6);
      p.policy.forget_half_life = half_life;
      WaveletMap map(p);
      wavog::ScanView v = wall.view();
      v.period = 1.0 / rate;
      map.integrate(wall.pose, v);
      const double g = map.forgetRate(v.period);
      const wavog::CellIndex cell = map.cellAt(3.03, 3.03 * std::tan(M_PI / 90));  // 2 deg
      // The first k with (1 - g)^k < 0.01: the Gaussian is there after k - 1 observations of
      // free space, gone after k + 1.
      const int k = static_cast<int>(std::floor(std::log(0.01) / std::log1p(-g))) + 1;
      if (half_life == 0.0) {
        EXPECT_EQ(k, 13);
      } else {
        EXPECT_NEAR(k * v.period, half_life * std::log2(100.0), 2.0 * v.period);
      }
      v = gone.view();
      v.period = 1.0 / rate;
      NdtCell c;
      for (int i = 1; i <= k + 1; ++i) {
        map.integrate(gone.pose, v);
        if (i != k - 1) continue;
        if (map.ndtCell(cell, &c)) {
          EXPECT_NEAR(c.weight, g * std::pow(1.0 - g, i), 1e-9 * c.weight);
        } else {
          ADD_FAILURE() << "gone after " << i << " observations, g " << g;
        }
      }
      EXPECT_FALSE(map.ndtCell(cell, &c)) << "after " << k + 1 << " observations";
    }
  }
}

TEST(Ndt, OffByDefaultAndOccupancyUnchangedWhenOn) {
  MapParams plain = MapParams::defaultsFor(PolicyType::kForget);
  plain.grid.resolution = 0.1;
  plain.grid.block_levels = 5;
  EXPECT_FALSE(plain.ndt);
  WaveletMap off(plain);
  EXPECT_THROW(off.exportNdt(0, CellBox{0, 0, 4, 4}), std::logic_error);
  MapParams with = plain;
  with.ndt = true;
  WaveletMap on(with);
  RandomScans scans(5u, 6.0);
  integrateScans(&scans, 60, off, on);
  expectSameCells(off, on, 60, 0.0);
  EXPECT_EQ(off.stats().ndt_bytes, 0u);
  EXPECT_GT(on.stats().ndt_bytes, 0u);
  EXPECT_EQ(on.stats().bytes - on.stats().ndt_bytes, off.stats().bytes);
}

TEST(Ndt, InvalidParametersNamed) {
  MapParams p = ndtParams(PolicyType::kForget, 0.1, 5);
  p.ndt_min_weight = -1.0;
  p.ndt_max_weight = 0.5;
  const auto errors = p.validate();
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_NE(errors[0].find("ndt_min_weight"), std::string::npos);
  EXPECT_NE(errors[1].find("ndt_max_weight"), std::string::npos);
  EXPECT_THROW(WaveletMap{p}, std::invalid_argument);
}

// Issue 38: the valid combinations that keep no Gaussian of a wall seen every scan are named with
// their values; every policy, half-life and floor up to 1 end-point keeps them and is not named.
TEST(Ndt, CombinationsThatKeepNoGaussianAreNamed) {
  for (PolicyType type : everyPolicyType()) {
    for (double half_life : {0.0, 60.0, 1e6}) {
      for (double min_weight : {0.0, 0.01, 1.0}) {
        MapParams p = ndtParams(type, 0.1, 5);
        p.policy.forget_half_life = half_life;
        p.ndt_min_weight = min_weight;
        p.ndt_max_weight = 1.0;
        EXPECT_TRUE(p.warnings().empty()) << wavog::toString(type) << " " << half_life;
      }
    }
    MapParams over = ndtParams(type, 0.1, 5);
    over.ndt_min_weight = 2.5;
    over.ndt_max_weight = 3.0;
    ASSERT_EQ(over.warnings().size(), 1u) << wavog::toString(type);
    EXPECT_NE(over.warnings()[0].find("ndt_min_weight (2.5) is over 1 end-point"),
              std::string::npos)
        << over.warnings()[0];
    over.ndt = false;
    EXPECT_TRUE(over.warnings().empty());
  }
  MapParams capped = ndtParams(PolicyType::kClampUpper, 0.1, 5);
  capped.ndt_min_weight = 5.0;
  capped.ndt_max_weight = 4.0;
  ASSERT_EQ(capped.warnings().size(), 1u);
  EXPECT_NE(capped.warnings()[0].find("ndt_max_weight (4) is under ndt_min_weight (5) with policy "
                                      "clamp_upper"),
            std::string::npos)
      << capped.warnings()[0];
  // What the warnings say: a floor over 1 keeps no Gaussian of one end-point per cell and scan,
  // a cap under the floor none at all.
  const OwnedScan wall = straightWall(3.03);
  MapParams over_one = ndtParams(PolicyType::kForget, 0.1, 6);
  over_one.ndt_min_weight = 1.5;
  for (const MapParams& p : {capped, over_one}) {
    WaveletMap map(p);
    for (int i = 0; i < 20; ++i) map.integrate(wall.pose, wall.view());
    EXPECT_EQ(map.stats().ndt_cells, 0u) << wavog::toString(p.policy.type);
  }
}

// Save and load: the Gaussians come back bit for bit, and the loaded map goes on as the original;
// a map without ndt reads the file too; clearing a box drops the Gaussians in it.
TEST(Ndt, FilesAndClearing) {
  const std::string path = ::testing::TempDir() + "ndt_" + std::to_string(::getpid());
  const MapParams p = ndtParams(PolicyType::kForget, 0.1, 5);
  WaveletMap map(p);
  RandomScans scans(77u, 6.0);
  integrateScans(&scans, 80, map);
  const CellBox box{-60, -60, 60, 60};
  map.save(path);
  WaveletMap loaded(p);
  loaded.load(path);
  integrateScans(&scans, 20, map, loaded);
  const auto a = map.exportNdt(0, box), b = loaded.exportNdt(0, box);
  ASSERT_EQ(a.cells.size(), b.cells.size());
  ASSERT_GT(a.cells.size(), 0u);
  for (std::size_t i = 0; i < a.cells.size(); ++i) {
    EXPECT_EQ(a.cells[i].weight, b.cells[i].weight) << i;
    EXPECT_EQ(a.cells[i].mean_x, b.cells[i].mean_x) << i;
    EXPECT_EQ(a.cells[i].cov_yy, b.cells[i].cov_yy) << i;
  }
  MapParams plain = p;
  plain.ndt = false;
  WaveletMap occupancy_only(plain);
  occupancy_only.load(path);
  EXPECT_EQ(occupancy_only.stats().ndt_cells, 0u);
  // Clearing: no Gaussian left with its cell centre in the box, the others kept.
  const std::size_t before = map.stats().ndt_cells;
  map.clearBox(-2.0, -2.0, 2.0, 2.0);
  const auto after = map.exportNdt(0, box);
  EXPECT_LT(after.cells.size(), before);
  EXPECT_GT(after.cells.size(), 0u);
  for (const NdtCell& c : after.cells) {
    const double x = (static_cast<double>(c.ix) + 0.5) * 0.1,
                 y = (static_cast<double>(c.iy) + 0.5) * 0.1;
    EXPECT_FALSE(x >= -2.0 && x <= 2.0 && y >= -2.0 && y <= 2.0) << c.ix << ", " << c.iy;
  }
  map.reset();
  EXPECT_EQ(map.stats().ndt_cells, 0u);
  std::remove(path.c_str());
}

// test/core/data/reflection_v2.wavog was saved by the format-version-2 code (before ndt) from the
// 30 scans of RandomScans(20261202, 6 m) with the "forget" defaults and reflection at 0.2 m,
// block_levels 6. A map with ndt loads it: the same occupancy and reflection (kept in the file's
// two layers), no Gaussian.
TEST(Ndt, FilesOfFormatVersion2StillLoad) {
  MapParams p = MapParams::defaultsFor(PolicyType::kForget);
  p.grid.resolution = 0.2;
  p.grid.block_levels = 6;
  p.reflection = true;
  WaveletMap made(p);
  RandomScans scans(20261202u, 6.0);
  integrateScans(&scans, 30, made);
  p.ndt = true;
  WaveletMap loaded(p);
  loaded.load(std::string(WAVOG_SOURCE_DIR) + "/test/core/data/reflection_v2.wavog");
  std::size_t observed = 0;
  for (std::int64_t y = -40; y < 40; ++y) {
    for (std::int64_t x = -40; x < 40; ++x) {
      // Up to the float round-off of the file's details (f32 before version 6).
      ASSERT_NEAR(loaded.value({x, y}), made.value({x, y}),
                  1e-6 * std::max(1.0f, std::fabs(made.value({x, y}))));
      ASSERT_EQ(loaded.isObserved({x, y}), made.isObserved({x, y}));
      // The file's hits and misses layers against today's hits with misses from the occupancy.
      const float a = loaded.reflection({x, y}), b = made.reflection({x, y});
      ASSERT_EQ(std::isnan(a), std::isnan(b));
      if (!std::isnan(a)) {
        ASSERT_NEAR(a, b, 1e-4);
      }
      observed += made.isObserved({x, y}) ? 1 : 0;
    }
  }
  EXPECT_GT(observed, 100u);
  EXPECT_EQ(loaded.stats().ndt_cells, 0u);
  EXPECT_EQ(loaded.stats().nodes, made.stats().nodes);
}

}  // namespace
}  // namespace wavog_test
