// The reflection probability map (MapParams::reflection): against a dense reference that counts
// hits and misses cell by cell (DenseReference layers with the spec's updates: "none" and the
// clamp policies add 1 to hits in the occupied band and to misses in free space, "forget" applies
// h <- (1-g) h + g [hit], m <- (1-g) m + g [miss], "max" counts hits only), for every policy, on
// random scans with every bad beam kind and on the first fr079 scans, at every scale; files,
// clearing and policy changes; off by default.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "dense_reference.h"
#include "test_support.h"

namespace wavog_test {
namespace {

using wavog::CellBox;
using wavog::MapParams;
using wavog::PolicyType;
using wavog::WaveletMap;

constexpr double kTolerance = 1e-4;

// The reference's counting layer: hits (or misses) of the spec for the map's policy.
MapParams countingLayer(const MapParams& main, bool hits) {
  MapParams p = main;
  p.policy.type = main.policy.type == PolicyType::kForget ? PolicyType::kForget : PolicyType::kNone;
  p.policy.init = wavog::InitValue::kUnknown;
  p.sensor.odd_occ = hits ? 1.0 : 0.0;
  p.sensor.odd_emp = hits ? 0.0 : 1.0;
  return p;
}

MapParams reflectionParams(PolicyType type, double res, int levels) {
  MapParams p = MapParams::defaultsFor(type);
  p.grid.resolution = res;
  p.grid.block_levels = levels;
  p.reflection = true;
  return p;
}

// p of the reference from its hits (layer 0) and misses (layer 1) over scale-s block (bx, by).
double referenceP(DenseReference* ref, bool hits_only, int s, std::int64_t bx, std::int64_t by) {
  if (!ref->blockAnyKnown(s, bx, by)) return std::numeric_limits<double>::quiet_NaN();
  ref->selectLayer(0);
  const double h = ref->blockMean(s, bx, by);
  if (hits_only) return h > 0.0 ? 1.0 : 0.0;
  ref->selectLayer(1);
  const double m = ref->blockMean(s, bx, by);
  return h / (h + m);
}

// Every scale-s cell inside the reference's extent: the tree's p equals the reference's (NaN on
// both sides where nothing was observed).
void expectSameReflection(const WaveletMap& map, DenseReference* ref, bool hits_only, int max_scale,
                          const std::string& what) {
  const CellBox& e = ref->extent();
  for (int s = 0; s <= max_scale; ++s) {
    const CellBox box{-((-e.min_x) >> s), -((-e.min_y) >> s), e.max_x >> s, e.max_y >> s};
    const wavog::ReflectionRaster r = map.exportReflection(s, box);
    ASSERT_EQ(r.p.size(), static_cast<std::size_t>(box.width() * box.height()));
    double worst = 0;
    std::size_t known_bad = 0, observed = 0;
    for (std::int64_t by = box.min_y; by < box.max_y; ++by) {
      for (std::int64_t bx = box.min_x; bx < box.max_x; ++bx) {
        const auto k = static_cast<std::size_t>((by - box.min_y) * box.width() + (bx - box.min_x));
        const double want = referenceP(ref, hits_only, s, bx, by);
        if (std::isnan(want) != std::isnan(r.p[k])) {
          ++known_bad;
          continue;
        }
        if (std::isnan(want)) continue;
        ++observed;
        worst = std::max(worst, std::fabs(r.p[k] - want));
        if (s == 0) {
          const float point = map.reflection({bx, by});
          worst = std::max(worst, std::fabs(point - want));
        }
      }
    }
    EXPECT_LE(worst, kTolerance) << what << " scale " << s;
    EXPECT_EQ(known_bad, 0u) << what << " scale " << s;
    EXPECT_GT(observed, 0u) << what << " scale " << s;
  }
}

struct ReflectionRun {
  MapParams params;
  WaveletMap map;
  DenseReference ref;
  bool hits_only;
  ReflectionRun(const MapParams& p, const CellBox& extent)
      : params(p),
        map(p),
        ref(std::vector<MapParams>{countingLayer(p, true), countingLayer(p, false)}, extent),
        hits_only(p.policy.type == PolicyType::kMax) {}
  void integrate(const OwnedScan& s) {
    map.integrate(s.pose, s.view());
    ref.integrate(s.pose, s.view());
  }
};

TEST(Reflection, RandomScansEveryPolicyEveryScale) {
  const double res = 0.1, half = 12.0;
  const auto cells = static_cast<std::int64_t>(std::ceil(half / res));
  for (int levels : {3, 5}) {
    for (PolicyType type : everyPolicyType()) {
      const std::string name = std::string(wavog::toString(type)) + " L" + std::to_string(levels);
      SCOPED_TRACE(name);
      ReflectionRun run(reflectionParams(type, res, levels), CellBox{-cells, -cells, cells, cells});
      RandomScans scans(31337u + static_cast<unsigned>(levels), half);
      for (int i = 0; i < 200; ++i) run.integrate(scans.next());
      expectSameReflection(run.map, &run.ref, run.hits_only, levels, name);
    }
  }
}

TEST(Reflection, Fr079FirstScansEveryPolicy) {
  const std::vector<OwnedScan> log = fr079Scans(300);
  ASSERT_EQ(log.size(), 300u);
  // The area of the first scans (fr079's first poses are near the origin, ranges < 50 m).
  const CellBox extent{-500, -500, 500, 500};
  for (PolicyType type : {PolicyType::kNone, PolicyType::kMax, PolicyType::kForget}) {
    SCOPED_TRACE(wavog::toString(type));
    ReflectionRun run(reflectionParams(type, 0.1, 6), extent);
    for (const OwnedScan& s : log) run.integrate(s);
    expectSameReflection(run.map, &run.ref, run.hits_only, 4, wavog::toString(type));
  }
}

TEST(Reflection, OffByDefaultAndOccupancyUnchangedWhenOn) {
  MapParams plain = MapParams::defaultsFor(PolicyType::kForget);
  plain.grid.resolution = 0.1;
  plain.grid.block_levels = 5;
  EXPECT_FALSE(plain.reflection);
  WaveletMap off(plain);
  EXPECT_THROW(off.exportReflection(0, CellBox{0, 0, 4, 4}), std::logic_error);
  MapParams with = plain;
  with.reflection = true;
  WaveletMap on(with);
  RandomScans scans(5u, 6.0);
  integrateScans(&scans, 60, off, on);
  // The occupancy is the same bit for bit; only the layers' bytes are added.
  expectSameCells(off, on, 60, 0.0);
  EXPECT_EQ(off.stats().reflection_bytes, 0u);
  EXPECT_GT(on.stats().reflection_bytes, 0u);
  EXPECT_EQ(on.stats().bytes - on.stats().reflection_bytes, off.stats().bytes);
  // Unknown reads -1, p reads 0..100.
  const auto grid = wavog::toOccupancyGrid(on.exportReflection(0, CellBox{-60, -60, 60, 60}));
  std::size_t unknown = 0, known = 0;
  for (auto v : grid) (v < 0 ? unknown : known) += 1;
  EXPECT_GT(unknown, 0u);
  EXPECT_GT(known, 0u);
}

TEST(Reflection, FilesClearingResetAndPolicyChanges) {
  const std::string path = ::testing::TempDir() + "reflection_" + std::to_string(::getpid());
  const MapParams p = reflectionParams(PolicyType::kForget, 0.1, 5);
  WaveletMap map(p);
  RandomScans scans(77u, 6.0);
  integrateScans(&scans, 80, map);
  const CellBox box{-60, -60, 60, 60};
  const auto before = map.exportReflection(0, box);
  map.save(path);
  WaveletMap loaded(p);
  loaded.load(path);
  const auto after = loaded.exportReflection(0, box);
  ASSERT_EQ(before.p.size(), after.p.size());
  for (std::size_t i = 0; i < before.p.size(); ++i) {
    ASSERT_TRUE((std::isnan(before.p[i]) && std::isnan(after.p[i])) || before.p[i] == after.p[i])
        << i;
  }
  // A map without reflection reads the same file (its layers are skipped) and the same occupancy.
  MapParams plain = p;
  plain.reflection = false;
  WaveletMap occupancy_only(plain);
  occupancy_only.load(path);
  EXPECT_EQ(occupancy_only.value({3, 4}), map.value({3, 4}));
  // Clearing a box clears its reflection; reset clears everything.
  loaded.clearBox(-1.0, -1.0, 1.0, 1.0);
  EXPECT_TRUE(std::isnan(loaded.reflection({0, 0})));
  EXPECT_FALSE(std::isnan(loaded.reflection(map.cellAt(3.05, 0.05))) &&
               std::isnan(map.reflection(map.cellAt(3.05, 0.05))));
  loaded.reset();
  const auto empty = loaded.exportReflection(0, box);
  for (float v : empty.p) ASSERT_TRUE(std::isnan(v));
  // forget -> max keeps the hits and drops the misses (p reads 1 where a beam ended, else 0).
  wavog::PolicyParams max_policy = p.policy;
  max_policy.type = PolicyType::kMax;
  map.setPolicy(max_policy, p.sensor);
  const auto hits_only = map.exportReflection(0, box);
  std::size_t ones = 0, zeros = 0;
  for (float v : hits_only.p) {
    if (std::isnan(v)) continue;
    ASSERT_TRUE(v == 0.0f || v == 1.0f) << v;
    (v == 1.0f ? ones : zeros) += 1;
  }
  EXPECT_GT(ones, 0u);
  EXPECT_GT(zeros, 0u);
  std::remove(path.c_str());
}

// Section 6.5 for the layers: a region seen empty long enough loses its detail in the hits and
// misses trees too (their odd values are 0 and 1, in either order).
TEST(Reflection, LongEmptyRunsCollapseTheLayersWithForgetting) {
  MapParams p = reflectionParams(PolicyType::kForget, 0.1, 5);
  p.sensor.no_return_clear = 12.0;  // the empty scans below clear without hits
  WaveletMap map(p);
  RandomScans scans(3u, 6.0);
  integrateScans(&scans, 60, map);
  const auto occupancyBytes = [&] { return map.stats().bytes - map.stats().reflection_bytes; };
  const double layers_before = static_cast<double>(map.stats().reflection_bytes);
  const double main_before = static_cast<double>(occupancyBytes());
  // Full circles from the origin with no return: free up to 12 m, no hit anywhere.
  OwnedScan empty;
  empty.angle_min = -3.14159;
  empty.angle_increment = 2 * 3.14159 / 2000;
  empty.range_min = 0.05;
  empty.range_max = 40.0;
  empty.ranges.assign(2000, std::numeric_limits<float>::infinity());
  for (int i = 0; i < 120; ++i) map.integrate(empty.pose, empty.view());
  // The two layers shrink as the occupancy tree does (which section 6.5 collapses).
  const double layers_ratio = static_cast<double>(map.stats().reflection_bytes) / layers_before;
  const double main_ratio = static_cast<double>(occupancyBytes()) / main_before;
  EXPECT_LT(main_ratio, 0.5);
  EXPECT_LT(layers_ratio, 1.25 * main_ratio)
      << "layers " << layers_before << " -> " << map.stats().reflection_bytes << " bytes, map "
      << main_before << " -> " << occupancyBytes();
  EXPECT_NEAR(map.reflection(map.cellAt(1.05, 2.05)), 0.0, 1e-6);
}

}  // namespace
}  // namespace wavog_test
