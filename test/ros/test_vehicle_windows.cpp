// A vehicle's window of the fleet map (vehicle_windows.h, issue 42): always the same number of
// cells, 2 round(fleet_window / resolution) + 1 per side, centred on the cell holding the
// vehicle, wherever the vehicle is in that cell. Before, each edge was rounded on its own: a
// 161-cell window was 160, 161 or 162 cells wide (centred at 27.2, 27.25 or 27.3 m).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>

#include "fleet/vehicle_windows.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace {

TEST(VehicleWindows, AWindowHasTheSameCellsWhereverItsCentreFalls) {
  for (double res : {0.05, 0.1, 0.03}) {
    wavog::MapParams params;
    params.grid.resolution = res;
    const wavog::WaveletMap map(params);
    for (double half : {4.0, 8.0, 0.05, 1.234}) {
      const std::int64_t side = 2 * std::llround(half / res) + 1;
      auto check = [&](double x, double y) {
        const wavog::CellBox b = wavog_fleet::windowCells(map, x, y, half);
        ASSERT_EQ(b.width(), side) << "res " << res << " half " << half << " at " << x;
        ASSERT_EQ(b.height(), side) << "res " << res << " half " << half << " at " << y;
        const std::int64_t cx = static_cast<std::int64_t>(std::floor(x / res));
        const std::int64_t cy = static_cast<std::int64_t>(std::floor(y / res));
        ASSERT_EQ(b.min_x + side / 2, cx) << x;  // the vehicle's cell in the middle
        ASSERT_EQ(b.min_y + side / 2, cy) << y;
      };
      // The centres, cell edges and centres, and random positions.
      for (double x : {27.2, 27.25, 27.3, 0.0, -0.0, -27.25, 27.225, 1e5 + 0.025}) check(x, x);
      std::mt19937_64 rng(7);
      std::uniform_real_distribution<double> pos(-2000.0, 2000.0);
      for (int i = 0; i < 20000; ++i) check(pos(rng), pos(rng));
    }
  }
  wavog::MapParams params;
  const wavog::WaveletMap map(params);
  EXPECT_TRUE(wavog_fleet::windowCells(map, std::nan(""), 0.0, 4.0).empty());
}

}  // namespace
