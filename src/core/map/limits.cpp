// Definitions of the extent and work limits (limits.h).
#include "wavog_mapping/core/limits.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace wavog {

std::int64_t clampedCellIndex(double cells) {
  const double limit = static_cast<double>(kCellIndexLimit);
  if (std::isnan(cells)) return kCellIndexLimit;
  return static_cast<std::int64_t>(std::clamp(cells, -limit - 1.0, limit));
}

double hardRangeLimit(const GridParams& grid, std::size_t beams) {
  const double block_cells = std::ldexp(1.0, grid.block_levels);
  const double budget_cells =
      kMaxScanBeamCells / static_cast<double>(std::max<std::size_t>(beams, 1));
  return std::min({kMaxRangeCells, kMaxRangeBlocks * block_cells, budget_cells}) * grid.resolution;
}

double hardRangeLimit(const MapParams& params, std::size_t beams, double angle_increment) {
  const GridParams& grid = params.grid;
  const double beam_limit = hardRangeLimit(grid, beams);
  const double band = std::max(params.sensor.band_width, grid.resolution) / grid.resolution;
  const double extra = band - 1.0;  // the one-cell band is in the per-beam-cell cost
  if (!(extra > 0.0)) return beam_limit;
  const double n = static_cast<double>(std::max<std::size_t>(beams, 1));
  // A fan is at most a whole turn (the scan's checks refuse more, and NaN).
  const double turn = 6.28318530717958647692;
  double fov = std::fabs(angle_increment) * n;
  if (!(fov <= turn)) fov = turn;
  const double cells =
      std::max(kMaxScanBeamCells - fov * extra * band / 2.0, 0.0) / (n + fov * extra);
  return std::min(beam_limit, cells * grid.resolution);
}

std::uint64_t readoutCells(const CellBox& window) {
  if (window.empty()) return 0;
  // max > min, so the unsigned differences are the exact widths (up to 2^64 - 1).
  const std::uint64_t w =
      static_cast<std::uint64_t>(window.max_x) - static_cast<std::uint64_t>(window.min_x);
  const std::uint64_t h =
      static_cast<std::uint64_t>(window.max_y) - static_cast<std::uint64_t>(window.min_y);
  if (w > std::numeric_limits<std::uint64_t>::max() / h) {
    return std::numeric_limits<std::uint64_t>::max();
  }
  return w * h;
}

}  // namespace wavog
