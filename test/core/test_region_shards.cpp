// Region shards (MapParams::region, issue 36): maps that integrate the same scans, each only into
// the blocks of its region, hold together, cell for cell and at every scale, the map of all blocks
// (occupancy, reflection probabilities, Gaussians), for every policy; a scan that reaches none of a
// region's blocks walks nothing and changes nothing; an invalid region is refused by name.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "test_support.h"
#include "wavog_mapping/core/limits.h"

namespace wavog_test {
namespace {

using wavog::BlockRegion;
using wavog::CellBox;
using wavog::MapParams;
using wavog::WaveletMap;

BlockRegion region(std::int64_t min_bx, std::int64_t min_by, std::int64_t max_bx,
                   std::int64_t max_by) {
  BlockRegion r;
  r.all = false;
  r.min_bx = min_bx;
  r.min_by = min_by;
  r.max_bx = max_bx;
  r.max_by = max_by;
  return r;
}

// The configurations: every policy and prior, forgetting eager and pruned, and the payloads
// (reflection layers and Gaussians, forgetting in seconds).
std::vector<NamedParams> configurations(double res, int levels) {
  return everyPolicyWithVariants(res, levels, {"forget", "none", "max", "clamp"});
}

// The cells of `r` at scale s (s <= block_levels, so a scale-s cell lies in one block).
CellBox regionCells(const BlockRegion& r, int levels, int s) {
  const int shift = levels - s;
  return CellBox{r.min_bx * (std::int64_t{1} << shift), r.min_by * (std::int64_t{1} << shift),
                 r.max_bx * (std::int64_t{1} << shift), r.max_by * (std::int64_t{1} << shift)};
}

CellBox intersect(const CellBox& a, const CellBox& b) {
  return CellBox{std::max(a.min_x, b.min_x), std::max(a.min_y, b.min_y),
                 std::min(a.max_x, b.max_x), std::min(a.max_y, b.max_y)};
}

// Every cell of `shard`'s region equals the whole map's at every scale, bit for bit: occupancy,
// observed flag, and with the payloads the reflection probabilities and the Gaussians' weights
// and means. Returns the observed finest cells compared.
std::size_t expectRegionEqual(const WaveletMap& whole, const WaveletMap& shard,
                              const BlockRegion& r, const std::string& what) {
  const MapParams& p = whole.params();
  const int L = p.grid.block_levels;
  std::size_t observed = 0;
  for (int s = 0; s <= L; ++s) {
    CellBox all;
    if (!whole.bounds(s, &all)) return 0;
    const CellBox box = intersect(all, regionCells(r, L, s));
    if (box.empty()) continue;
    const wavog::Raster a = whole.exportScale(s, box, wavog::Aggregation::kMean);
    const wavog::Raster b = shard.exportScale(s, box, wavog::Aggregation::kMean);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < a.log_odds.size(); ++i) {
      if (s == 0) observed += a.known[i];
      differ += a.known[i] != b.known[i] ||
                std::memcmp(&a.log_odds[i], &b.log_odds[i], sizeof(float)) != 0;
    }
    EXPECT_EQ(differ, 0u) << what << ": scale " << s << ", cells that differ of "
                          << a.log_odds.size();
    if (p.reflection) {
      const wavog::ReflectionRaster ra = whole.exportReflection(s, box);
      const wavog::ReflectionRaster rb = shard.exportReflection(s, box);
      EXPECT_TRUE(ra.p.size() == rb.p.size() &&
                  std::memcmp(ra.p.data(), rb.p.data(), ra.p.size() * sizeof(float)) == 0)
          << what << ": reflection, scale " << s;
    }
    if (p.ndt) {
      const wavog::NdtLayer na = whole.exportNdt(s, box);
      const wavog::NdtLayer nb = shard.exportNdt(s, box);
      EXPECT_EQ(na.cells.size(), nb.cells.size()) << what << ": Gaussians, scale " << s;
      for (std::size_t i = 0; i < std::min(na.cells.size(), nb.cells.size()); ++i) {
        EXPECT_EQ(na.cells[i].weight, nb.cells[i].weight) << what << ": Gaussian " << i;
        EXPECT_EQ(na.cells[i].mean_x, nb.cells[i].mean_x) << what << ": Gaussian " << i;
        EXPECT_EQ(na.cells[i].mean_y, nb.cells[i].mean_y) << what << ": Gaussian " << i;
      }
    }
  }
  // Nothing outside the region.
  CellBox sb;
  if (shard.bounds(L, &sb)) {
    EXPECT_GE(sb.min_x, r.min_bx) << what;
    EXPECT_GE(sb.min_y, r.min_by) << what;
    EXPECT_LE(sb.max_x, r.max_bx) << what;
    EXPECT_LE(sb.max_y, r.max_by) << what;
  }
  return observed;
}

// Layouts of 2, 3 and 4 shards that tile the extent, in blocks.
std::vector<std::vector<BlockRegion>> layouts(int levels) {
  const std::int64_t lim = wavog::kCellIndexLimit >> levels;
  return {
      {region(-lim, -lim, 0, lim), region(0, -lim, lim, lim)},
      {region(-lim, -lim, -3, lim), region(-3, -lim, 5, lim), region(5, -lim, lim, lim)},
      {region(-lim, -lim, 1, -2), region(1, -lim, lim, -2), region(-lim, -2, 1, lim),
       region(1, -2, lim, lim)},
  };
}

TEST(RegionShards, ShardsTogetherEqualTheWholeMapCellForCellForEveryPolicy) {
  constexpr int kLevels = 4;  // blocks of 1.6 m at 0.1 m: scans of +-20 m reach many
  for (const auto& np : configurations(0.1, kLevels)) {
    for (const auto& layout : layouts(kLevels)) {
      const std::string what = np.name + ", " + std::to_string(layout.size()) + " shards";
      WaveletMap whole(np.params);
      std::vector<std::unique_ptr<WaveletMap>> shards;
      for (const BlockRegion& r : layout) {
        MapParams q = np.params;
        q.region = r;
        shards.push_back(std::make_unique<WaveletMap>(q));
      }
      RandomScans scans(23, 40.0);
      for (int i = 0; i < 60; ++i) {
        const OwnedScan s = scans.next();
        const wavog::IntegrateStats st = whole.integrate(s.pose, s.view());
        std::uint32_t blocks = 0;
        for (auto& shard : shards) {
          const wavog::IntegrateStats ss = shard->integrate(s.pose, s.view());
          ASSERT_EQ(ss.status, st.status) << what;
          blocks += ss.blocks_touched;
          EXPECT_EQ(ss.outside_region, st.status == wavog::ScanStatus::kOk && ss.touched.empty())
              << what;
        }
        // Each block of the scan is in exactly one shard.
        EXPECT_EQ(blocks, st.blocks_touched) << what << ", scan " << i;
        if (i == 30) {  // clearing is per block too
          whole.clearBox(-8.0, -6.0, 5.0, 9.0);
          for (auto& shard : shards) shard->clearBox(-8.0, -6.0, 5.0, 9.0);
        }
      }
      std::size_t observed = 0;
      for (std::size_t k = 0; k < layout.size(); ++k) {
        observed += expectRegionEqual(whole, *shards[k], layout[k],
                                      what + ", shard " + std::to_string(k));
      }
      EXPECT_EQ(observed, whole.stats(true).observed_cells) << what;
      EXPECT_GT(observed, 20000u) << what;
    }
  }
}

TEST(RegionShards, AScanThatMissesTheRegionWalksNothingAndChangesNothing) {
  MapParams p = MapParams::defaultsFor(wavog::PolicyType::kForget);
  p.grid.resolution = 0.1;
  p.grid.block_levels = 4;
  p.region = region(100, 100, 110, 110);  // 160 m away
  WaveletMap shard(p);
  RandomScans scans(3, 20.0);
  for (int i = 0; i < 20; ++i) {
    const OwnedScan s = scans.next();
    const wavog::IntegrateStats st = shard.integrate(s.pose, s.view());
    EXPECT_EQ(st.status, wavog::ScanStatus::kOk);
    EXPECT_TRUE(st.outside_region);
    EXPECT_EQ(st.nodes_visited, 0u);
    EXPECT_EQ(st.blocks_touched, 0u);
    EXPECT_TRUE(st.touched.empty());
  }
  EXPECT_EQ(shard.stats().blocks, 0u);
  EXPECT_EQ(shard.stats().nodes_visited_last, 0u);
}

TEST(RegionShards, AScanTheCoreRefusesIsRefusedAlikeOutsideTheRegion) {
  MapParams p = MapParams::defaultsFor(wavog::PolicyType::kClamp);
  p.grid.resolution = 0.1;
  p.grid.block_levels = 4;
  MapParams q = p;
  q.region = region(100, 100, 110, 110);
  WaveletMap whole(p), shard(q);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<float> ranges(180, 5.0f);
  const auto view = [&](double angle_increment, double range_min, double range_max) {
    return wavog::ScanView{ranges.data(), ranges.size(), -M_PI / 2, angle_increment, range_min,
                           range_max};
  };
  struct Case {
    wavog::Pose2 pose;
    wavog::ScanView view;
    wavog::ScanStatus status;
  };
  std::vector<Case> cases = {
      {{0, 0, 0}, view(M_PI / 180, 0.1, 30), wavog::ScanStatus::kOk},
      {{0, 0, 0}, view(0.0, 0.1, 30), wavog::ScanStatus::kBadGeometry},
      {{0, 0, 0}, view(0.1, 0.1, 30), wavog::ScanStatus::kBadGeometry},
      {{0, 0, 0}, view(M_PI / 180, 0.1, 0.05), wavog::ScanStatus::kBadGeometry},
      {{nan, 0, 0}, view(M_PI / 180, 0.1, 30), wavog::ScanStatus::kBadPose},
      {{0, 0, inf}, view(M_PI / 180, 0.1, 30), wavog::ScanStatus::kBadPose},
      {{2e8, 0, 0}, view(M_PI / 180, 0.1, 30), wavog::ScanStatus::kOutOfExtent},
      {{0, 0, 0}, view(M_PI / 180, 6.0, 30), wavog::ScanStatus::kNoValidBeam},  // all below
      {{0, 0, 0}, view(M_PI / 180, 0.1, 4.0), wavog::ScanStatus::kNoValidBeam},  // no return
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    const wavog::IntegrateStats a = whole.integrate(c.pose, c.view);
    const wavog::IntegrateStats b = shard.integrate(c.pose, c.view);
    EXPECT_EQ(a.status, c.status) << "case " << i;
    EXPECT_EQ(b.status, c.status) << "case " << i;
    EXPECT_EQ(b.outside_region, c.status == wavog::ScanStatus::kOk) << "case " << i;
  }
  // Every beam a no-return, cleared 10 m: valid, and outside the region.
  p.sensor.no_return_clear = q.sensor.no_return_clear = 10.0;
  WaveletMap clearing(q);
  const wavog::IntegrateStats st = clearing.integrate({0, 0, 0}, view(M_PI / 180, 0.1, 4.0));
  EXPECT_EQ(st.status, wavog::ScanStatus::kOk);
  EXPECT_TRUE(st.outside_region);
}

TEST(RegionShards, AScanJustReachingTheRegionIsIntegratedThere) {
  // Returns at 4.84 m, reach 4.89 m with the half band: into the blocks from x = 4.8 m by a few
  // cells, so the shard of those blocks takes the scan (prepared: its beams counted) and changes
  // them as the whole map does; the next blocks' shard skips it before preparation.
  MapParams p = MapParams::defaultsFor(wavog::PolicyType::kNone);
  p.grid.resolution = 0.1;
  p.grid.block_levels = 4;  // blocks of 1.6 m
  std::vector<float> ranges(180, 4.84f);
  const wavog::ScanView v{ranges.data(), ranges.size(), -M_PI / 2, M_PI / 180, 0.1, 30.0};
  MapParams in = p, out = p;
  in.region = region(3, -2, 4, 2);   // x in [4.8, 6.4)
  out.region = region(4, -2, 5, 2);  // x in [6.4, 8.0)
  WaveletMap whole(p), a(in), b(out);
  whole.integrate({0.0, 0.0, 0.0}, v);
  const wavog::IntegrateStats sa = a.integrate({0.0, 0.0, 0.0}, v);
  const wavog::IntegrateStats sb = b.integrate({0.0, 0.0, 0.0}, v);
  EXPECT_FALSE(sa.outside_region);
  EXPECT_EQ(sa.beams_hit, 180u);
  EXPECT_GT(sa.nodes_visited, 0u);
  EXPECT_TRUE(sb.outside_region);
  EXPECT_EQ(sb.beams_hit, 0u);  // not prepared
  EXPECT_EQ(sb.nodes_visited, 0u);
  EXPECT_GT(expectRegionEqual(whole, a, in.region, "edge"), 0u);
}

TEST(RegionShards, TouchedBoxIsClippedToTheRegion) {
  MapParams p = MapParams::defaultsFor(wavog::PolicyType::kNone);
  p.grid.resolution = 0.1;
  p.grid.block_levels = 4;
  p.region = region(0, 0, 4, 4);  // cells [0, 64)^2
  WaveletMap shard(p);
  const std::vector<float> ranges(360, 5.0f);
  const wavog::ScanView view{ranges.data(), ranges.size(), -M_PI, M_PI / 180.0, 0.1, 30.0};
  const wavog::IntegrateStats st = shard.integrate(wavog::Pose2{0.0, 0.0, 0.0}, view);
  ASSERT_EQ(st.status, wavog::ScanStatus::kOk);
  EXPECT_FALSE(st.outside_region);
  EXPECT_EQ(st.touched.min_x, 0);
  EXPECT_EQ(st.touched.min_y, 0);
  EXPECT_GT(st.touched.max_x, 40);
  EXPECT_LE(st.touched.max_x, 64);
  EXPECT_GT(st.blocks_touched, 8u);  // of the region's 4 x 4 blocks: those within 5 m
  EXPECT_LE(st.blocks_touched, 16u);
}

TEST(RegionShards, AnInvalidRegionIsRefusedByName) {
  MapParams p;
  p.grid.block_levels = 9;
  for (const BlockRegion& r : {region(0, 0, 0, 5), region(3, 0, 2, 5),
                               region(0, 0, (wavog::kCellIndexLimit >> 9) + 1, 5)}) {
    p.region = r;
    const auto errors = p.validate();
    ASSERT_EQ(errors.size(), 1u);
    EXPECT_NE(errors[0].find("region"), std::string::npos) << errors[0];
    EXPECT_THROW(WaveletMap{p}, std::invalid_argument);
  }
  p.region = region(-2, -2, 2, 2);
  EXPECT_TRUE(p.validate().empty());
  p.region.all = true;  // the bounds are then unused
  p.region.max_bx = -5;
  EXPECT_TRUE(p.validate().empty());
}

}  // namespace
}  // namespace wavog_test
