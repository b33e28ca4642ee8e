// Ground truth of a simulated world rasterised on a grid of finest cells, with the core's cell
// convention: cell (ix, iy) covers [ix, ix+1) x [iy, iy+1) * resolution in the world frame.
// Pure functions over values; thread-safe.
#ifndef WAVOG_MAPPING_SIM_GROUND_TRUTH_H_
#define WAVOG_MAPPING_SIM_GROUND_TRUTH_H_

#include <cstdint>
#include <vector>

#include "wavog_mapping/sim/geometry.h"
#include "wavog_mapping/sim/world.h"

namespace wavog {
namespace sim {

/// A window of cells at one resolution, row-major (y rows, x fastest).
struct GridWindow {
  double resolution = 0.1;  ///< cell size (m)
  std::int64_t min_x = 0;   ///< index of the first column
  std::int64_t min_y = 0;   ///< index of the first row
  int width = 0;            ///< columns
  int height = 0;           ///< rows

  /// The smallest window covering the rectangle [min, max] (m).
  static GridWindow covering(const Vec2& min, const Vec2& max, double resolution);
  std::size_t size() const { return static_cast<std::size_t>(width) * height; }
  /// Centre of window cell (col, row) in the world frame.
  Vec2 centre(int col, int row) const;
  /// Window position of a world point; false if outside.
  bool locate(const Vec2& p, int* col, int* row) const;
  std::size_t index(int col, int row) const { return static_cast<std::size_t>(row) * width + col; }
};

/// 1 where the cell centre lies inside one of `polygons`, else 0.
std::vector<std::uint8_t> rasteriseFilled(const std::vector<Polygon>& polygons,
                                          const GridWindow& window);
/// 1 where an edge of one of `polygons` passes through the cell (the surface lasers can see).
std::vector<std::uint8_t> rasteriseBoundary(const std::vector<Polygon>& polygons,
                                            const GridWindow& window);

/// Which objects to draw.
enum class TruthFilter {
  kAll,        ///< every object present
  kWallsOnly,  ///< the static structure (ObjectKind::kWall)
};

/// Filled occupancy of the world at time t.
std::vector<std::uint8_t> occupancyAt(const World& world, double t, const GridWindow& window,
                                      TruthFilter filter = TruthFilter::kAll);
/// Surface (boundary) cells of the world at time t.
std::vector<std::uint8_t> surfaceAt(const World& world, double t, const GridWindow& window,
                                    TruthFilter filter = TruthFilter::kAll);

/// Per cell, the distance (m) from its centre to the nearest cell set in `mask` (0 on set cells;
/// +inf if `mask` is empty). Exact Euclidean distance transform (Felzenszwalb-Huttenlocher).
std::vector<float> distanceTransform(const std::vector<std::uint8_t>& mask,
                                     const GridWindow& window);

}  // namespace sim
}  // namespace wavog

#endif  // WAVOG_MAPPING_SIM_GROUND_TRUTH_H_
