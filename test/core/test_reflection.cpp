// The reflection probability map (MapParams::reflection): against a dense reference that counts
// hits and misses cell by cell (DenseReference layers with the spec's updates: "none" and the
// clamp policies add 1 to hits in the occupied band and to misses in free space, the clamps then
// scale both down to a total of clamp_min / odd_emp ("clamp", "clamp_lower"), from m = prior /
// odd_emp; "forget" applies h <- (1-g) h + g [hit], m <- (1-g) m + g [miss] from h = m = 0, or
// m = 1 with the empty_bound prior, "max" counts hits only), for every policy and prior, on random
// scans with every bad beam kind and on the first fr079 scans, at every scale; restarts after
// policy changes; files of every mode, clearing; off by default.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "../../src/core/payloads/reflection_store.h"
#include "dense_reference.h"
#include "test_support.h"

namespace wavog_test {
namespace {

using wavog::CellBox;
using wavog::MapParams;
using wavog::PolicyType;
using wavog::WaveletMap;

constexpr double kTolerance = 1e-4;

// The reference's counting layer: hits (or misses) of the spec for the map's policy. With
// forgetting and the empty_bound prior a cell starts as one full miss (the layer's empty bound).
MapParams countingLayer(const MapParams& main, bool hits) {
  MapParams p = main;
  const bool forget = main.policy.type == PolicyType::kForget;
  p.policy.type = forget ? PolicyType::kForget : PolicyType::kNone;
  p.policy.init = forget ? main.policy.init : wavog::InitValue::kUnknown;
  p.sensor.odd_occ = hits ? 1.0 : 0.0;
  p.sensor.odd_emp = hits ? 0.0 : 1.0;
  return p;
}

// The clamps: the reference's counts bounded in total as the map's are, reset at the
// occupancy's (layer 2's) empty bound, misses from those the prior stands for (none after a
// restart).
void boundCounts(const MapParams& p, DenseReference* ref, bool restarted) {
  const PolicyType t = p.policy.type;
  if (t != PolicyType::kClamp && t != PolicyType::kClampLower && t != PolicyType::kClampUpper)
    return;
  if (t != PolicyType::kClampUpper) {
    ref->boundCounts(p.policy.clamp_min / p.sensor.odd_emp, 2, p.policy.clamp_min);
  }
  if (!restarted) ref->setInitial(1, p.initValue() / p.sensor.odd_emp);
}

MapParams reflectionParams(PolicyType type, double res, int levels,
                           wavog::InitValue init = wavog::InitValue::kUnknown) {
  MapParams p = MapParams::defaultsFor(type);
  p.policy.init = init;
  p.grid.resolution = res;
  p.grid.block_levels = levels;
  p.reflection = true;
  return p;
}

// p of the reference from its hits (layer 0) and misses (layer 1) over scale-s block (bx, by),
// and the tolerance of the tree's: kTolerance, plus, where the misses are read from the occupancy
// (every policy but "max" since the map was empty), the occupancy's own tolerance carried through
// m = (L - prior - odd_occ h) / odd_emp (or L / odd_emp): kTolerance times the largest |L| of the
// block's cells (at least 1; |L| <= |prior| + odd_occ h + |odd_emp| m, hundreds under "none"), over
// |odd_emp| and the block's mean count.
double referenceP(DenseReference* ref, const MapParams& p, bool hits_only, int s, std::int64_t bx,
                  std::int64_t by, double* tolerance) {
  *tolerance = kTolerance;
  if (!ref->blockAnyKnown(s, bx, by)) return std::numeric_limits<double>::quiet_NaN();
  ref->selectLayer(0);
  const double h = ref->blockMean(s, bx, by);
  if (hits_only) return h > 0.0 ? 1.0 : 0.0;
  ref->selectLayer(1);
  const double m = ref->blockMean(s, bx, by);
  double largest = 1.0;
  const std::int64_t size = std::int64_t{1} << s;
  for (std::int64_t y = by * size; y < (by + 1) * size; ++y) {
    for (std::int64_t x = bx * size; x < (bx + 1) * size; ++x) {
      ref->selectLayer(0);
      const double hc = ref->value(x, y);
      ref->selectLayer(1);
      const double mc = ref->value(x, y);
      largest = std::max(largest,
                         std::fabs(p.initValue()) + p.sensor.odd_occ * hc - p.sensor.odd_emp * mc);
    }
  }
  *tolerance += kTolerance * largest / (-p.sensor.odd_emp * (h + m));
  return h / (h + m);
}

// Every scale-s cell inside the reference's extent: the tree's p equals the reference's (NaN on
// both sides where nothing was observed).
void expectSameReflection(const WaveletMap& map, DenseReference* ref, bool hits_only, int max_scale,
                          const std::string& what) {
  const MapParams& params = map.params();
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
        double tolerance = kTolerance;
        const double want = referenceP(ref, params, hits_only, s, bx, by, &tolerance);
        if (std::isnan(want) != std::isnan(r.p[k])) {
          ++known_bad;
          continue;
        }
        if (std::isnan(want)) continue;
        ++observed;
        // Errors in units of the cell's tolerance: the worst must stay within 1.
        worst = std::max(worst, std::fabs(r.p[k] - want) * kTolerance / tolerance);
        if (s == 0) {
          const float point = map.reflection({bx, by});
          worst = std::max(worst, std::fabs(point - want) * kTolerance / tolerance);
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
  // `restarted`: the map's reflection map restarted, from no counts whatever the prior.
  ReflectionRun(const MapParams& p, const CellBox& extent, bool restarted = false)
      : params(p),
        map(p),
        ref(std::vector<MapParams>{countingLayer(p, true), countingLayer(p, false), p}, extent),
        hits_only(p.policy.type == PolicyType::kMax) {
    boundCounts(p, &ref, restarted);
  }
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
      for (wavog::InitValue init : {wavog::InitValue::kUnknown, wavog::InitValue::kEmptyBound}) {
        const std::string name = std::string(wavog::toString(type)) + " L" +
                                 std::to_string(levels) + " " + wavog::toString(init);
        SCOPED_TRACE(name);
        ReflectionRun run(reflectionParams(type, res, levels, init),
                          CellBox{-cells, -cells, cells, cells});
        RandomScans scans(31337u + static_cast<unsigned>(levels), half);
        for (int i = 0; i < 200; ++i) run.integrate(scans.next());
        expectSameReflection(run.map, &run.ref, run.hits_only, levels, name);
      }
    }
  }
}

// A change of policy, odd values or prior restarts the reflection map (from no counts, in a mode
// that does not read the occupancy, whose history is another policy's): from then on it equals a
// reference started at the change.
TEST(Reflection, PolicyChangesRestartItExactly) {
  const double res = 0.1, half = 12.0;
  const auto cells = static_cast<std::int64_t>(std::ceil(half / res));
  const CellBox extent{-cells, -cells, cells, cells};
  const std::vector<std::pair<PolicyType, PolicyType>> changes = {
      {PolicyType::kClamp, PolicyType::kForget},
      {PolicyType::kForget, PolicyType::kNone},
      {PolicyType::kNone, PolicyType::kClamp},
      {PolicyType::kForget, PolicyType::kClampLower},
      {PolicyType::kNone, PolicyType::kClampUpper},
      {PolicyType::kForget, PolicyType::kForget}};  // the same policy, another odd_occ
  for (const auto& change : changes) {
    const std::string name =
        std::string(wavog::toString(change.first)) + " -> " + wavog::toString(change.second);
    SCOPED_TRACE(name);
    const MapParams before = reflectionParams(change.first, res, 4);
    MapParams after = reflectionParams(change.second, res, 4);
    if (change.first == change.second) after.sensor.odd_occ += 0.25;
    WaveletMap map(before);
    // The reference's occupancy (layer 2) has the map's whole history; its counts start at the
    // change.
    ReflectionRun run(after, extent, true);
    run.ref.setLayerParams(2, before);
    RandomScans scans(99u, half);
    for (int i = 0; i < 60; ++i) {
      const OwnedScan s = scans.next();
      map.integrate(s.pose, s.view());
      run.ref.integrate(s.pose, s.view());
    }
    map.setPolicy(after.policy, after.sensor);
    run.ref.setLayerParams(2, after);
    run.ref.setInitial(0, 0.0);
    run.ref.setInitial(1, 0.0);
    run.ref.forgetKnowledge();
    // Restarted: no count anywhere (NaN, or 0 where the occupancy's knowledge remains).
    for (float v : map.exportReflection(0, extent).p) ASSERT_TRUE(std::isnan(v) || v == 0.0f);
    for (int i = 0; i < 120; ++i) {
      const OwnedScan s = scans.next();
      map.integrate(s.pose, s.view());
      run.ref.integrate(s.pose, s.view());
    }
    expectSameReflection(map, &run.ref, false, 4, name);
    // A gamma change keeps it: only the rate of the following scans changes.
    if (change.second == PolicyType::kForget) {
      wavog::PolicyParams slower = after.policy;
      slower.gamma = 0.1;
      map.setPolicy(slower, after.sensor);
      run.ref.setGamma(0, 0.1);
      run.ref.setGamma(1, 0.1);
      for (int i = 0; i < 40; ++i) {
        const OwnedScan s = scans.next();
        map.integrate(s.pose, s.view());
        run.ref.integrate(s.pose, s.view());
      }
      expectSameReflection(map, &run.ref, false, 4, name + ", gamma 0.1");
    }
    // So does a change of the clamps' bound: the counts are bounded anew from the next scan.
    if (change.second == PolicyType::kClamp) {
      wavog::PolicyParams tighter = after.policy;
      tighter.clamp_min = -1.2;
      map.setPolicy(tighter, after.sensor);
      MapParams occupancy = after;
      occupancy.policy = tighter;
      run.ref.setLayerParams(2, occupancy);
      run.ref.boundCounts(tighter.clamp_min / after.sensor.odd_emp, 2, tighter.clamp_min);
      for (int i = 0; i < 40; ++i) {
        const OwnedScan s = scans.next();
        map.integrate(s.pose, s.view());
        run.ref.integrate(s.pose, s.view());
      }
      expectSameReflection(map, &run.ref, false, 4, name + ", clamp_min -1.2");
      // A lowered clamp_max: a cell above it falls to it at its next observation (a miss that
      // counts one, however far it falls).
      tighter.clamp_max = 1.0;
      map.setPolicy(tighter, after.sensor);
      occupancy.policy = tighter;
      run.ref.setLayerParams(2, occupancy);
      for (int i = 0; i < 40; ++i) {
        const OwnedScan s = scans.next();
        map.integrate(s.pose, s.view());
        run.ref.integrate(s.pose, s.view());
      }
      expectSameReflection(map, &run.ref, false, 4, name + ", clamp_max 1.0");
    }
  }
}

TEST(Reflection, RealDataFr079FirstScansEveryPolicy) {
  const std::vector<OwnedScan> log = fr079Scans(500);
  ASSERT_EQ(log.size(), 500u);
  // The area of the first scans (fr079's first poses are near the origin, ranges < 50 m).
  const CellBox extent{-500, -500, 500, 500};
  for (PolicyType type : everyPolicyType()) {
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
  // forget -> max restarts from no hits; then p reads 1 where a beam ended, else 0.
  wavog::PolicyParams max_policy = p.policy;
  max_policy.type = PolicyType::kMax;
  map.setPolicy(max_policy, p.sensor);
  for (float v : map.exportReflection(0, box).p) ASSERT_TRUE(std::isnan(v) || v == 0.0f);
  integrateScans(&scans, 20, map);
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

// Every way the reflection map is kept (misses from the occupancy under "none", "forget" and the
// clamps, h from it alone under "forget" with the empty_bound prior, hits only under "max", a
// misses layer or two layers after a restart) survives a round trip bit for bit; a map of
// another basis (odd values) restarts it on loading, as a policy change would.
TEST(Reflection, FilesKeepEveryModeAndRestartOnAnotherBasis) {
  const std::string path = ::testing::TempDir() + "reflection_modes_" + std::to_string(::getpid());
  struct Case {
    PolicyType type;
    wavog::InitValue init;
    bool restarted;
  };
  const std::vector<Case> cases = {{PolicyType::kNone, wavog::InitValue::kUnknown, false},
                                   {PolicyType::kForget, wavog::InitValue::kUnknown, false},
                                   {PolicyType::kForget, wavog::InitValue::kEmptyBound, false},
                                   {PolicyType::kClamp, wavog::InitValue::kUnknown, false},
                                   {PolicyType::kClamp, wavog::InitValue::kEmptyBound, false},
                                   {PolicyType::kClampUpper, wavog::InitValue::kUnknown, false},
                                   {PolicyType::kMax, wavog::InitValue::kUnknown, false},
                                   {PolicyType::kForget, wavog::InitValue::kUnknown, true},
                                   {PolicyType::kNone, wavog::InitValue::kUnknown, true},
                                   {PolicyType::kClamp, wavog::InitValue::kUnknown, true},
                                   {PolicyType::kClampUpper, wavog::InitValue::kUnknown, true}};
  const CellBox box{-60, -60, 60, 60};
  for (const Case& c : cases) {
    const std::string name = std::string(wavog::toString(c.type)) + " " + wavog::toString(c.init) +
                             (c.restarted ? " restarted" : "");
    SCOPED_TRACE(name);
    MapParams p = reflectionParams(c.type, 0.1, 5, c.init);
    WaveletMap map(p);
    RandomScans scans(123u, 6.0);
    if (c.restarted) {
      MapParams before = reflectionParams(
          c.type == PolicyType::kClamp ? PolicyType::kNone : PolicyType::kClamp, 0.1, 5);
      map.setPolicy(before.policy, before.sensor);
      integrateScans(&scans, 30, map);
      map.setPolicy(p.policy, p.sensor);
    }
    integrateScans(&scans, 60, map);
    map.save(path);
    WaveletMap loaded(p);
    loaded.load(path);
    const auto before = map.exportReflection(2, box), after = loaded.exportReflection(2, box);
    const auto cells_before = map.exportReflection(0, box),
               cells_after = loaded.exportReflection(0, box);
    std::size_t known = 0;
    for (std::size_t i = 0; i < cells_before.p.size(); ++i) {
      ASSERT_TRUE((std::isnan(cells_before.p[i]) && std::isnan(cells_after.p[i])) ||
                  cells_before.p[i] == cells_after.p[i])
          << i;
      known += std::isnan(cells_before.p[i]) ? 0 : 1;
    }
    for (std::size_t i = 0; i < before.p.size(); ++i) {
      ASSERT_TRUE((std::isnan(before.p[i]) && std::isnan(after.p[i])) || before.p[i] == after.p[i]);
    }
    EXPECT_GT(known, 100u);
    EXPECT_LE(loaded.stats().reflection_bytes, map.stats().reflection_bytes);  // tight vectors
    EXPECT_GE(2 * loaded.stats().reflection_bytes, map.stats().reflection_bytes);
    // Both go on the same way (under the clamps to float round-off: the file holds each pair
    // brought up to date at the save, the map still as of its last hit, and the misses since are
    // counted in closed form from there).
    integrateScans(&scans, 10, map, loaded);
    const auto go_on = map.exportReflection(0, box), go_on_loaded = loaded.exportReflection(0, box);
    const bool clamps = c.type == PolicyType::kClamp || c.type == PolicyType::kClampLower ||
                        c.type == PolicyType::kClampUpper;
    const float round_off = clamps ? 1e-6f : 0.0f;
    for (std::size_t i = 0; i < go_on.p.size(); ++i) {
      ASSERT_TRUE((std::isnan(go_on.p[i]) && std::isnan(go_on_loaded.p[i])) ||
                  std::fabs(go_on.p[i] - go_on_loaded.p[i]) <= round_off)
          << i << ": " << go_on.p[i] << " against " << go_on_loaded.p[i];
    }
    // Another odd_occ: the file's counts do not hold under it, the reflection map restarts.
    MapParams other = p;
    other.sensor.odd_occ += 0.25;
    WaveletMap elsewhere(other);
    elsewhere.load(path);
    for (float v : elsewhere.exportReflection(0, box).p) ASSERT_TRUE(std::isnan(v) || v == 0.0f);
  }
  std::remove(path.c_str());
}

// The clamps bound a cell's count, not its hits and misses apart (paper section 1.3.3): a cell
// that returns every other beam reads p about 1/2 however long it is watched, its count stays at
// clamp_min / odd_emp, after it stops returning p falls by that count's window, and once its
// occupancy reaches the empty bound it reads as a cell never hit.
TEST(Reflection, ClampsBoundTheCountKeepingTheRatio) {
  MapParams p = reflectionParams(PolicyType::kClamp, 0.1, 5);
  const double bound = p.policy.clamp_min / p.sensor.odd_emp;  // 5 with the defaults
  ASSERT_NEAR(bound, 5.0, 1e-12);
  WaveletMap map(p);
  // One beam along +x from (0, 0.05): ending in the cell at x = 2.05, or crossing it.
  OwnedScan beam;
  beam.pose = {0.0, 0.05, 0.0};
  beam.angle_min = 0.0;
  beam.angle_increment = 0.01;
  beam.range_min = 0.05;
  beam.range_max = 30.0;
  const auto shoot = [&](float range) {
    beam.ranges.assign(1, range);
    map.integrate(beam.pose, beam.view());
  };
  const wavog::CellIndex cell = map.cellAt(2.05, 0.05);
  for (int i = 0; i < 400; ++i) shoot(i % 2 == 0 ? 2.05f : 4.05f);
  // The alternation's fixed points with a count of 5: p = 5/11 after a miss, 6/11 after a hit.
  EXPECT_NEAR(map.reflection(cell), 5.0 / 11.0, 1e-5);
  shoot(2.05f);
  const float after_hit = map.reflection(cell);
  shoot(4.05f);
  const float after_miss = map.reflection(cell);
  EXPECT_NEAR(after_hit, 6.0 / 11.0, 1e-5);
  EXPECT_NEAR(after_miss, 5.0 / 11.0, 1e-5);
  // Misses only: the hits scale by 5/6 each.
  for (int i = 0; i < 12; ++i) shoot(4.05f);
  EXPECT_NEAR(map.reflection(cell), after_miss * std::pow(5.0 / 6.0, 12), 1e-5);
  // Its occupancy was at clamp_max = 3.5; two more misses take it to clamp_min (3.5 - 14 * 0.4
  // < -2), where the cell reads as never hit.
  EXPECT_GT(map.value(cell), p.policy.clamp_min + 0.1);
  shoot(4.05f);
  shoot(4.05f);
  EXPECT_EQ(map.value(cell), static_cast<float>(p.policy.clamp_min));
  EXPECT_EQ(map.reflection(cell), 0.0f);
  // Without the clamps' bound ("none"), the same history reads p = 1/2 only on average and
  // barely moves after 12 misses: the counts remember all 400 beams.
  MapParams none = reflectionParams(PolicyType::kNone, 0.1, 5);
  WaveletMap counting(none);
  for (int i = 0; i < 401; ++i) {
    beam.ranges.assign(1, i % 2 == 0 ? 2.05f : 4.05f);
    counting.integrate(beam.pose, beam.view());
  }
  for (int i = 0; i < 13; ++i) {
    beam.ranges.assign(1, 4.05f);
    counting.integrate(beam.pose, beam.view());
  }
  EXPECT_NEAR(counting.reflection(cell), 201.0 / 414.0, 1e-4);
}

// test/core/data/clamp_reflection_v4.wavog was saved by the format-version-4 code (unbounded
// counts under the clamps, in a misses layer) from the 30 scans of RandomScans(20261202, 6 m) with
// the "clamp" defaults and reflection at 0.2 m, block_levels 6. It loads with the same occupancy;
// its reflection map restarts (its counts mean something else now) and from then on equals a
// reference started at the load.
TEST(Reflection, ClampFilesOfFormatVersion4Restart) {
  MapParams p = reflectionParams(PolicyType::kClamp, 0.2, 6);
  const CellBox extent{-40, -40, 40, 40};
  ReflectionRun run(p, extent, true);
  RandomScans scans(20261202u, 6.0);
  for (int i = 0; i < 30; ++i) {
    const OwnedScan s = scans.next();
    run.ref.integrate(s.pose, s.view());
  }
  WaveletMap loaded(p);
  loaded.load(std::string(WAVOG_SOURCE_DIR) + "/test/core/data/clamp_reflection_v4.wavog");
  WaveletMap made(p);
  RandomScans again(20261202u, 6.0);
  integrateScans(&again, 30, made);
  // Up to the float round-off of the file's details (f32 before version 6).
  expectSameCells(made, loaded, 30, 1e-6);
  for (float v : loaded.exportReflection(0, extent).p) ASSERT_TRUE(std::isnan(v));
  run.ref.setInitial(0, 0.0);
  run.ref.setInitial(1, 0.0);
  run.ref.forgetKnowledge();
  for (int i = 0; i < 40; ++i) {
    const OwnedScan s = again.next();
    loaded.integrate(s.pose, s.view());
    run.ref.integrate(s.pose, s.view());
  }
  expectSameReflection(loaded, &run.ref, false, 4, "v4 clamp file");
}

// Section 6.5 for the reflection map: a region seen empty long enough loses its hits too (their
// entries are swept once the block has had no hit for a while), as the occupancy loses its detail.
TEST(Reflection, LongEmptyRunsShrinkItWithForgetting) {
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
  // The hits shrink as the occupancy tree does (which section 6.5 collapses).
  const double layers_ratio = static_cast<double>(map.stats().reflection_bytes) / layers_before;
  const double main_ratio = static_cast<double>(occupancyBytes()) / main_before;
  EXPECT_LT(main_ratio, 0.5);
  EXPECT_LT(layers_ratio, 1.25 * main_ratio)
      << "layers " << layers_before << " -> " << map.stats().reflection_bytes << " bytes, map "
      << main_before << " -> " << occupancyBytes();
  EXPECT_NEAR(map.reflection(map.cellAt(1.05, 2.05)), 0.0, 1e-6);
}

// The closed form of the clamps' pairs against the misses applied one by one (m + 1, then h and m
// scaled to keep h + m <= bound), from counts under the bound and from counts above it (a file's,
// or a bound just lowered); less than half a miss of log-odds (a huge e.l's float round-off) is
// no miss. A fuzzed file once saved such a pair as m < 0, a file the loader refuses.
TEST(Reflection, PairClosedFormEqualsMissesOneByOne) {
  const double odd_emp = -0.4, bound = 5.0, no_bound = -std::numeric_limits<double>::infinity();
  for (const auto& start : std::vector<std::pair<float, float>>{{1.0f, 0.0f}, {2.5f, 1.5f},
                                                               {6.5f, 0.0f}, {4.0f, 3.0f}}) {
    wavog::detail::HitPair e;
    e.h = start.first;
    e.m = start.second;
    e.l = 2.0f;
    double h = e.h, m = e.m;
    for (int n = 0; n <= 40; ++n) {
      SCOPED_TRACE("h " + std::to_string(e.h) + " m " + std::to_string(e.m) + " n " +
                   std::to_string(n));
      const wavog::detail::PairCounts c =
          wavog::detail::pairNow(e, e.l + n * odd_emp, odd_emp, bound, no_bound);
      EXPECT_NEAR(c.h, h, 1e-5 * bound);
      EXPECT_NEAR(c.m, m, 1e-5 * bound);
      EXPECT_GE(c.m, 0.0);
      m += 1.0;
      const double f = std::min(1.0, bound / (h + m));
      h *= f;
      m *= f;
    }
    const wavog::detail::PairCounts off = wavog::detail::pairNow(e, e.l + 0.45 * odd_emp, odd_emp,
                                                                 bound, no_bound);
    EXPECT_EQ(off.h, e.h);
    EXPECT_EQ(off.m, e.m);
  }
}

}  // namespace
}  // namespace wavog_test
