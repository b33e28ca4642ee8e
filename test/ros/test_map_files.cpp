// The names and crop shared by ~save_map and wavog_offline (wavog_io, map_files.h): gtest only.
#include <gtest/gtest.h>

#include "wavog_mapping/io/map_files.h"

namespace {

/// A w x h raster at box origin (x0, y0) whose known cells are those listed.
wavog::Raster raster(std::int64_t x0, std::int64_t y0, int w, int h,
                     const std::vector<std::pair<int, int>>& known) {
  wavog::Raster r;
  r.scale = 1;
  r.cell_size = 0.2;
  r.box = {x0, y0, x0 + w, y0 + h};
  r.log_odds.assign(static_cast<std::size_t>(w * h), 0.0f);
  r.known.assign(r.log_odds.size(), 0);
  for (const auto& k : known) {
    const auto i = static_cast<std::size_t>(k.second * w + k.first);
    r.known[i] = 1;
    r.log_odds[i] = static_cast<float>(k.first + 10 * k.second);
  }
  return r;
}

TEST(MapFiles, NamesFollowOneScheme) {
  EXPECT_EQ(wavog::scaleFileBase("out/map", 0), "out/map_s0");
  EXPECT_EQ(wavog::scaleFileBase("room", 3), "room_s3");
  EXPECT_EQ(wavog::pathStem("/tmp/a.b/room.wavog"), "/tmp/a.b/room");
  EXPECT_EQ(wavog::pathStem("/tmp/a.b/room"), "/tmp/a.b/room");
  EXPECT_EQ(wavog::pathStem("room.wavog"), "room");
  EXPECT_EQ(wavog::pathStem("/tmp/.hidden"), "/tmp/.hidden");
}

TEST(MapFiles, CropKeepsTheKnownBoxAndTheMargin) {
  const wavog::Raster r = raster(-5, 7, 10, 8, {{3, 2}, {6, 4}});
  wavog::CellBox k;
  ASSERT_TRUE(wavog::knownBox(r, &k));
  EXPECT_EQ(k.min_x, -5 + 3);
  EXPECT_EQ(k.max_x, -5 + 7);
  EXPECT_EQ(k.min_y, 7 + 2);
  EXPECT_EQ(k.max_y, 7 + 5);

  const wavog::Raster c0 = wavog::cropToKnown(r, 0);
  EXPECT_EQ(c0.box.width(), 4);
  EXPECT_EQ(c0.box.height(), 3);
  EXPECT_EQ(c0.scale, 1);
  EXPECT_DOUBLE_EQ(c0.cell_size, 0.2);
  // Values travel with their cells.
  EXPECT_EQ(c0.known[0], 1);
  EXPECT_FLOAT_EQ(c0.log_odds[0], 3.0f + 20.0f);
  EXPECT_EQ(c0.known[2 * 4 + 3], 1);
  EXPECT_FLOAT_EQ(c0.log_odds[2 * 4 + 3], 6.0f + 40.0f);

  // Margin 2, clipped to the raster: x 1..8 of 10, y 0..6 of 8.
  const wavog::Raster c2 = wavog::cropToKnown(r, 2);
  EXPECT_EQ(c2.box.min_x, -5 + 1);
  EXPECT_EQ(c2.box.max_x, -5 + 9);
  EXPECT_EQ(c2.box.min_y, 7 + 0);
  EXPECT_EQ(c2.box.max_y, 7 + 7);
  EXPECT_EQ(c2.known.size(), static_cast<std::size_t>(8 * 7));
}

TEST(MapFiles, NothingKnownLeavesTheRaster) {
  const wavog::Raster r = raster(0, 0, 4, 3, {});
  wavog::CellBox k;
  EXPECT_FALSE(wavog::knownBox(r, &k));
  EXPECT_EQ(wavog::cropToKnown(r).box.width(), 4);
  EXPECT_EQ(wavog::cropToKnown(r).box.height(), 3);
}

}  // namespace
