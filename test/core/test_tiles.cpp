// The dense leaf tiles (storage/tile.h): float under the bounded policies, double under the
// unbounded ones. A policy change between the two converts every tile and changes no cell; a file
// saved by a map of one kind loads into a map of the other with the same cells.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <string>

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

}  // namespace
}  // namespace wavog_test
