// Wall sharpness of an occupancy map: the width at half maximum of the occupancy profile across
// straight walls, and where the profiles are taken (from a simulated world's true walls, or from
// a reference map's straight occupied stretches when there is no ground truth, as on real logs);
// how far the occupied cells and their NDT means lie from the true walls.
// Profiles read P(occ) = 1 / (1 + exp(-log-odds)), so unbounded log-odds (policy none) and
// bounded ones are measured alike. Units: metres; widths in cells of the raster. Pure functions
// over values; thread-safe. ROS-free.
#ifndef WAVOG_MAPPING_SIM_WALL_METRICS_H_
#define WAVOG_MAPPING_SIM_WALL_METRICS_H_

#include <cstddef>
#include <limits>
#include <vector>

#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/sim/geometry.h"
#include "wavog_mapping/sim/world.h"

namespace wavog {
namespace sim {

/// A place on a wall: a point on its surface and the unit normal pointing into free space (or
/// either way, when `two_sided`).
struct WallSample {
  Vec2 point = Vec2::Zero();
  Vec2 normal = Vec2::UnitX();
  bool two_sided = false;
};

/// Where and how far the profiles reach.
struct WallProfileOptions {
  double spacing_m = 0.5;       ///< distance between samples along a wall (m), > 0
  double min_length_m = 1.5;    ///< walls (edges) shorter than this are skipped (m)
  double end_margin_m = 0.5;    ///< no samples this close to an edge's ends (m)
  double inside_m = 0.5;        ///< the profile reaches this far behind the surface (m)
  double outside_m = 1.0;       ///< and this far into free space (m)
  double peak_window_m = 0.25;  ///< the peak is looked for this close to the surface (m)
};

/// Samples on the faces of the world's walls (ObjectKind::kWall present at t) that face free
/// space: the profile's free side must not enter any object present at t.
std::vector<WallSample> wallSamplesFromWorld(const World& world, double t,
                                             const WallProfileOptions& options);

/// Samples on straight walls of a reference map without ground truth: occupied cells
/// (log-odds > 0) whose occupied neighbours within `radius_m` lie along a line (ratio of the
/// principal second moments >= `min_linearity`), at most one per `options.spacing_m` square;
/// the point is the neighbours' centroid, the normal the minor axis, two-sided.
std::vector<WallSample> wallSamplesFromMap(const Raster& reference,
                                           const WallProfileOptions& options, double radius_m = 0.4,
                                           double min_linearity = 25.0);

/// Width at half maximum of the profiles across the walls.
struct WallWidth {
  double mean_cells = 0.0;    ///< mean width over the measured profiles (cells)
  double median_cells = 0.0;  ///< median width (cells)
  std::size_t samples = 0;    ///< profiles asked for
  std::size_t measured = 0;   ///< profiles with an observed occupied peak and free side
};

/// For each sample: P(occ) along the normal from -inside_m to +outside_m (both sides by
/// max(inside_m, outside_m) when two-sided) at the raster's cell size, nearest cell; the peak is
/// the highest observed value within peak_window_m of the point and must be > 0.5; the base is
/// the lowest observed value on the free side. The width is the number of consecutive observed
/// samples around the peak at or above (peak + base) / 2. Unobserved cells end a run.
WallWidth wallWidthAtHalfMax(const Raster& map, const std::vector<WallSample>& samples,
                             const WallProfileOptions& options);

/// Mean distance (m) from the map's occupied cells (observed, log-odds > 1e-3) that lie within
/// `margin_m` of a wall present at t, and nearer to a wall than to any other object, to the
/// nearest cell a wall's surface passes through (0 on the surface, inside or outside alike; 0
/// is ideal). `cells` (if given) receives the number of cells averaged. 0 when there are none.
double meanDistanceToWallSurface(const World& world, double t, const Raster& map,
                                 double margin_m = 1.0, std::size_t* cells = nullptr);

/// How far the map puts the walls from their true surfaces, cell centres against NDT means
/// (paper section 1.2.3: NDT cells reduce the grid's discretisation error). Distances are exact,
/// from a point to the nearest edge of a wall (ObjectKind::kWall present at t), inside or
/// outside alike. NaN where nothing was averaged.
struct NdtWallDistance {
  /// Mean distance of the centres of the occupied cells near walls (as in
  /// meanDistanceToWallSurface: observed, log-odds > 1e-3, within the margin of a wall and
  /// nearer to a wall than to any other object).
  double cell_centre_m = std::numeric_limits<double>::quiet_NaN();
  std::size_t cells = 0;  ///< cells averaged in cell_centre_m
  /// The same over those of the cells that hold a Gaussian (the cells of ndt_mean_m).
  double ndt_cell_centre_m = std::numeric_limits<double>::quiet_NaN();
  /// Mean distance of the Gaussians' means of those cells.
  double ndt_mean_m = std::numeric_limits<double>::quiet_NaN();
  std::size_t gaussians = 0;  ///< Gaussians averaged in ndt_mean_m
};

/// Cell centres and NDT means of `map` against the world's walls at t. `ndt` is the map's
/// exportNdt at the raster's scale (same cell size; Gaussians outside the raster are ignored).
NdtWallDistance ndtWallDistance(const World& world, double t, const Raster& map,
                                const NdtLayer& ndt, double margin_m = 1.0);

/// Distance (m) from `p` to the nearest edge of a wall present at t; +inf without walls.
double distanceToWallEdges(const World& world, double t, const Vec2& p);

}  // namespace sim
}  // namespace wavog

#endif  // WAVOG_MAPPING_SIM_WALL_METRICS_H_
