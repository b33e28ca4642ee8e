// The dense leaf tiles (storage/tile.h): float under the bounded policies, double under the
// unbounded ones. A policy change between the two converts every tile and changes no cell; a file
// saved by a map of one kind loads into a map of the other with the same cells. The AVX2 update of
// a float tile gives the SSE2 one's values and sum, bit for bit.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <random>
#include <string>

#include "../../src/core/update/tile_update.h"
#include "test_support.h"

namespace wavog_test {
namespace {

using wavog::MapParams;
using wavog::PolicyType;
using wavog::WaveletMap;

constexpr int kHalf = 60;  // cells: the random scans' square of 2.5 m at 5 cm, and a margin

MapParams tileParams(PolicyType type) {
  MapParams p = MapParams::defaultsFor(type);
  p.grid.resolution = 0.05;
  p.grid.block_levels = 5;  // several blocks, tiles under two levels of nodes
  return p;
}

TEST(Tiles, PolicyChangesConvertTilesAndKeepEveryCell) {
  // clamp (float tiles) -> clamp_lower (double) -> clamp: every cell as in a map left under clamp
  // all along, after each change and after more scans.
  WaveletMap changed(tileParams(PolicyType::kClamp)), kept(tileParams(PolicyType::kClamp));
  RandomScans scans(7, 2.5);
  integrateScans(&scans, 60, changed, kept);
  ASSERT_GT(changed.stats().nodes, 100u);
  const std::size_t tiles = changed.stats().tiles;
  ASSERT_GT(tiles, 10u);
  EXPECT_LT(tiles, changed.stats().nodes);
  const std::size_t float_bytes = changed.stats().bytes;
  const MapParams wide = tileParams(PolicyType::kClampLower);
  changed.setPolicy(wide.policy, wide.sensor);
  expectSameCells(changed, kept, kHalf, 0.0);
  const std::size_t wide_bytes = changed.stats().bytes;
  EXPECT_GT(wide_bytes, float_bytes + float_bytes / 4) << "double tiles take more room";
  EXPECT_EQ(changed.stats().tiles, tiles) << "converted, not dropped or added";
  changed.setPolicy(kept.params().policy, kept.params().sensor);
  expectSameCells(changed, kept, kHalf, 0.0);
  EXPECT_LT(changed.stats().bytes, wide_bytes);
  integrateScans(&scans, 40, changed, kept);
  expectSameCells(changed, kept, kHalf, 0.0);
}

TEST(Tiles, FilesLoadIntoMapsOfTheOtherKind) {
  const std::string path =
      ::testing::TempDir() + "wavog_tiles_" + std::to_string(::getpid()) + ".wavog";
  RandomScans scans(11, 2.5);
  WaveletMap narrow(tileParams(PolicyType::kClamp)), wide(tileParams(PolicyType::kNone));
  integrateScans(&scans, 60, narrow, wide);
  for (const WaveletMap* saved : {&narrow, &wide}) {
    saved->save(path);
    for (const PolicyType type : {PolicyType::kClamp, PolicyType::kNone}) {
      SCOPED_TRACE(wavog::toString(saved->params().policy.type) + std::string(" into ") +
                   wavog::toString(type));
      WaveletMap loaded(tileParams(type));
      loaded.load(path);
      // A double tile's values rounded to float (and back) on loading into a float map.
      const bool rounded = saved == &wide && type == PolicyType::kClamp;
      expectSameCells(loaded, *saved, kHalf, rounded ? 1e-6 : 0.0);
      EXPECT_EQ(loaded.stats().tiles, saved->stats().tiles);
    }
  }
  std::remove(path.c_str());
}

#if defined(WAVOG_TILE_AVX2) && defined(__SSE2__)
// Random tiles (some values at the file bound), random E / O masks (rows whole, partial and
// empty), random shifted constants: both paths give the same stored floats and the same sum of
// changes, so a map does not depend on the CPU it was made on.
template <PolicyType P>
void expectAvx2LikeSse2(std::uint32_t seed) {
  using wavog::detail::FloatTile;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> value(-8.0, 8.0), unit(0.0, 1.0);
  int changed = 0;
  for (int trial = 0; trial < 5000; ++trial) {
    wavog::detail::ShiftedPolicy sp{};
    const double shift = value(rng);
    sp.odd_occ = 0.5 + 3.0 * unit(rng) + (P == PolicyType::kMax ? shift : 0.0);
    sp.odd_emp = -0.2 - 3.0 * unit(rng) + (P == PolicyType::kMax ? shift : 0.0);
    sp.lo = -4.0 * unit(rng) + shift;
    sp.hi = 4.0 * unit(rng) + shift;
    sp.a = unit(rng);
    sp.add_occ = 3.0 * unit(rng) + (1.0 - sp.a) * shift;
    sp.add_emp = -3.0 * unit(rng) + (1.0 - sp.a) * shift;
    FloatTile sse{}, avx{};
    for (float& v : sse.v) {
      const double pick = unit(rng);
      v = pick < 0.02   ? wavog::detail::kMaxStoredFloat
          : pick < 0.04 ? -wavog::detail::kMaxStoredFloat
                        : static_cast<float>(value(rng));
    }
    avx = sse;
    std::uint64_t seen = rng(), occ = rng();
    for (unsigned row = 0; row < 64; row += 8) {  // some rows whole, some unseen
      const std::uint64_t k = rng() % 4;
      if (k == 0) seen |= std::uint64_t{0xFF} << row;
      if (k == 1) seen &= ~(std::uint64_t{0xFF} << row);
    }
    const std::uint64_t o = seen & occ, e = seen & ~occ;
    const double sum_sse = wavog::detail::updateTileCellsSse2<P>(sp, &sse, e, o);
    const double sum_avx = wavog::detail::tile_avx2::update<P>(sp, &avx, e, o);
    ASSERT_EQ(std::memcmp(sse.v, avx.v, sizeof sse.v), 0) << "trial " << trial;
    ASSERT_EQ(std::memcmp(&sum_sse, &sum_avx, sizeof sum_sse), 0)
        << "trial " << trial << ": " << sum_sse << " against " << sum_avx;
    changed += sum_sse != 0.0;
  }
  EXPECT_GT(changed, 4000) << "the updates changed the tiles";
}

TEST(Tiles, Avx2UpdateIsTheSse2UpdateBitForBit) {
  if (!wavog::detail::tile_avx2::available()) GTEST_SKIP() << "this CPU has no AVX2";
  expectAvx2LikeSse2<PolicyType::kClamp>(1u);
  expectAvx2LikeSse2<PolicyType::kForget>(2u);
  expectAvx2LikeSse2<PolicyType::kMax>(3u);
  expectAvx2LikeSse2<PolicyType::kNone>(4u);
}
#endif

}  // namespace
}  // namespace wavog_test
