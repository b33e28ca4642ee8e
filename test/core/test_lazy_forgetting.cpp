// Lazy forgetting (ALGORITHM.md section 6): tags instead of visits, closed form eq. 1.7,
// equality with eager forgetting and with the reference, pruning of long-empty regions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <tuple>

#include "../../src/core/storage/cell_reader.h"
#include "dense_reference.h"
#include "map_access.h"
#include "test_support.h"

namespace wavog_test {
namespace {

using wavog::MapParams;
using wavog::WaveletMap;

constexpr double kPi = 3.14159265358979323846;

// A 360-degree scan of a square room of half-size `half` centred on the sensor pose, plus a
// few pillars: lots of detail near the walls.
OwnedScan roomScan(const wavog::Pose2& pose, double half, int beams = 720) {
  OwnedScan s;
  s.pose = pose;
  s.angle_min = -kPi;
  s.angle_increment = 2 * kPi / beams;
  s.range_min = 0.05;
  s.range_max = 30.0;
  for (int j = 0; j < beams; ++j) {
    const double b = pose.theta + s.angle_min + j * s.angle_increment;
    const double c = std::fabs(std::cos(b)), sn = std::fabs(std::sin(b));
    double r = half / std::max(c, sn);
    if (j % 37 < 3) r *= 0.6;  // pillars
    s.ranges.push_back(static_cast<float>(r));
  }
  return s;
}

// A narrow scan from far away whose free space covers the room: every beam returns at 25 m.
OwnedScan farEmptyScan() {
  OwnedScan s;
  s.pose = {-12.0, 0.3, 0.0};
  s.angle_min = -0.5;
  s.angle_increment = 1.0 / 200;
  s.range_min = 0.05;
  s.range_max = 30.0;
  s.ranges.assign(201, 25.0f);
  return s;
}

MapParams forgetParams(bool lazy, double tau = 0.0) {
  MapParams p = MapParams::defaultsFor(wavog::PolicyType::kForget);
  p.grid.resolution = 0.05;
  p.grid.block_levels = 7;
  p.lazy_forgetting = lazy;
  p.prune_threshold = tau;
  return p;
}

struct NodeKey {
  const void* addr;
  bool operator<(const NodeKey& o) const { return addr < o.addr; }
};

TEST(LazyForgetting, EmptyScansTagNodesAndLeaveStoredDetailsUntouched) {
  WaveletMap map(forgetParams(true));
  for (int i = 0; i < 5; ++i)
    map.integrate({0.1 * i, 0.05 * i, 0.1 * i}, roomScan({0.1 * i, 0.05 * i, 0.1 * i}, 2.0).view());
  std::map<const void*, std::tuple<double, double, double, int>> before;
  wavog::MapAccess::forEachNode(map, [&](const wavog::detail::Node& n, int, int pending) {
    before[&n] = {n.d[0], n.d[1], n.d[2], pending};
  });
  ASSERT_GT(before.size(), 100u);
  const OwnedScan e = farEmptyScan();
  map.integrate(e.pose, e.view());
  std::size_t tagged = 0, untouched = 0;
  wavog::MapAccess::forEachNode(map, [&](const wavog::detail::Node& n, int, int pending) {
    auto it = before.find(&n);
    if (it == before.end()) return;
    const auto& [d0, d1, d2, was] = it->second;
    if (pending > was) {
      ++tagged;
      // Stored details of a tagged subtree are not rewritten; only the count moved.
      if (n.d[0] == d0 && n.d[1] == d1 && n.d[2] == d2) ++untouched;
    }
  });
  EXPECT_GT(tagged, 50u);
  EXPECT_EQ(untouched, tagged);
}

TEST(LazyForgetting, ClosedFormEqualsEagerSteps) {
  WaveletMap lazy(forgetParams(true)), eager(forgetParams(false));
  std::vector<OwnedScan> scans;
  for (int i = 0; i < 5; ++i) scans.push_back(roomScan({0.1 * i, -0.05 * i, 0.2 * i}, 2.0));
  for (const auto& s : scans) {
    lazy.integrate(s.pose, s.view());
    eager.integrate(s.pose, s.view());
  }
  // Values before the empty run, then n fully-empty scans.
  const int n = 7;
  std::vector<std::pair<wavog::CellIndex, double>> cells;
  for (std::int64_t y = -40; y < 40; y += 3)
    for (std::int64_t x = -40; x < 40; x += 3) cells.push_back({{x, y}, lazy.value({x, y})});
  const OwnedScan e = farEmptyScan();
  for (int i = 0; i < n; ++i) {
    lazy.integrate(e.pose, e.view());
    eager.integrate(e.pose, e.view());
  }
  const MapParams p = forgetParams(true);
  const double a = 1 - p.policy.gamma;
  for (const auto& [c, v0] : cells) {
    const double closed = std::pow(a, n) * (v0 - p.sensor.odd_emp) + p.sensor.odd_emp;  // eq. 1.7
    EXPECT_NEAR(lazy.value(c), closed, 1e-4) << c.x << "," << c.y;
    EXPECT_NEAR(eager.value(c), lazy.value(c), 1e-4) << c.x << "," << c.y;
  }
}

// The reflection map's sweeps read many cells of a block at once (BlockCellReader): each read
// must give what WaveletMap::Impl::read gives, through pending tags (the far empty scans) and
// pruned subtrees (tau > 0), whatever the order of the cells.
TEST(LazyForgetting, BlockCellReaderReadsWhatReadReads) {
  WaveletMap map(forgetParams(true, 0.01));
  for (int i = 0; i < 4; ++i) {
    const wavog::Pose2 pose{0.1 * i, 0.05 * i, 0.1 * i};
    map.integrate(pose, roomScan(pose, 2.0).view());
  }
  const OwnedScan e = farEmptyScan();
  for (int i = 0; i < 3; ++i) map.integrate(e.pose, e.view());
  const wavog::WaveletMap::Impl& impl = wavog::MapAccess::impl(map);
  std::size_t pending = 0;
  wavog::MapAccess::forEachNode(
      map, [&](const wavog::detail::Node& n, int, int) { pending += n.k != 0 ? 1 : 0; });
  ASSERT_GT(pending, 10u);  // tags to read through
  const std::uint32_t cells = 1u << (2 * impl.levels);
  std::mt19937 rng(7);
  std::size_t compared = 0, detailed = 0;
  for (const auto& kv : impl.blocks) {
    const std::int64_t x0 = wavog::detail::scaleUp(wavog::detail::blockKeyX(kv.first), impl.levels);
    const std::int64_t y0 = wavog::detail::scaleUp(wavog::detail::blockKeyY(kv.first), impl.levels);
    std::vector<std::uint32_t> codes(cells);
    for (std::uint32_t c = 0; c < cells; ++c) codes[c] = c;
    for (int order = 0; order < 2; ++order) {
      if (order == 1) std::shuffle(codes.begin(), codes.end(), rng);
      wavog::detail::BlockCellReader reader(impl, kv.second);
      for (std::uint32_t c : codes) {
        std::uint32_t lx, ly;
        wavog::detail::mortonCell(c, &lx, &ly);
        const double want = impl.read(0, x0 + lx, y0 + ly).average;
        const double got = reader.average(c);
        ASSERT_EQ(got, want) << "block " << x0 << "," << y0 << " cell " << lx << "," << ly;
        ++compared;
        detailed += want != kv.second.s ? 1 : 0;
      }
    }
  }
  EXPECT_GT(compared, 10000u);
  EXPECT_GT(detailed, 1000u);  // cells that differ from their block's mean
}

TEST(LazyForgetting, RepeatedEmptyScansCostDoesNotGrowWithDetail) {
  // Same empty scans over a detailed region (after the room scans) and over a region that was
  // only ever seen empty: the lazy update visits about as many nodes; eager visits far more.
  WaveletMap detailed(forgetParams(true)), plain(forgetParams(true)), eager(forgetParams(false));
  for (int i = 0; i < 5; ++i) {
    const auto s = roomScan({0.1 * i, 0.05 * i, 0.1 * i}, 2.0);
    detailed.integrate(s.pose, s.view());
    eager.integrate(s.pose, s.view());
  }
  const OwnedScan e = farEmptyScan();
  plain.integrate(e.pose, e.view());
  detailed.integrate(e.pose, e.view());
  eager.integrate(e.pose, e.view());
  const auto visits_plain = plain.integrate(e.pose, e.view()).nodes_visited;
  const auto visits_detailed = detailed.integrate(e.pose, e.view()).nodes_visited;
  const auto visits_eager = eager.integrate(e.pose, e.view()).nodes_visited;
  const auto nodes = detailed.stats().nodes;
  EXPECT_LE(visits_detailed, visits_plain + visits_plain / 10) << "nodes in map " << nodes;
  EXPECT_GT(visits_eager, visits_detailed + nodes / 2);
}

TEST(LazyForgetting, LongEmptyRunsPruneWithinBound) {
  for (double tau : {0.0, 0.01, 0.05}) {
    WaveletMap map(forgetParams(true, tau));
    MapParams p = forgetParams(true, tau);
    const wavog::CellBox extent{-80, -80, 80, 80};  // the room
    DenseReference ref(p, extent);
    for (int i = 0; i < 5; ++i) {
      const auto s = roomScan({0.1 * i, 0.05 * i, 0.1 * i}, 2.0);
      map.integrate(s.pose, s.view());
      ref.integrate(s.pose, s.view());
    }
    const OwnedScan e = farEmptyScan();
    // The smallest tree for what the empty scans leave: a map that only ever saw them.
    WaveletMap minimal(p);
    for (int i = 0; i < 120; ++i) minimal.integrate(e.pose, e.view());
    map.integrate(e.pose, e.view());  // adds the far scan's own field-of-view boundary
    ref.integrate(e.pose, e.view());
    std::size_t last_nodes = map.stats().nodes;
    const std::size_t start_nodes = last_nodes;
    bool monotone = true;
    for (int i = 1; i < 120; ++i) {
      map.integrate(e.pose, e.view());
      ref.integrate(e.pose, e.view());
      const std::size_t now = map.stats().nodes;
      if (i > 0 && now > last_nodes) monotone = false;
      last_nodes = now;
    }
    EXPECT_TRUE(monotone) << "tau " << tau;
    // Long-empty regions collapse: forgetting drives details to zero and the counter reaches K*:
    // the room's detail is gone, only the far scan's own boundary remains.
    EXPECT_LT(last_nodes, start_nodes) << "tau " << tau;
    EXPECT_LE(last_nodes, minimal.stats().nodes + 4) << "tau " << tau;
    const Comparison c = compare(map, ref);
    // Documented bound: 1.25 * tau * block_levels per pruning, plus float round-off.
    const double bound = 1.25 * std::max(tau, 1e-6) * p.grid.block_levels / p.policy.gamma + 1e-4;
    EXPECT_LE(c.max_rel_error * std::max(1.0, std::fabs(p.sensor.odd_occ)), bound) << "tau " << tau;
    EXPECT_EQ(c.knowledge_mismatches, 0u);
  }
}

}  // namespace
}  // namespace wavog_test
