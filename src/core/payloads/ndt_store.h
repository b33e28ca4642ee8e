// The storage of normal-distribution cells (MapParams::ndt): each block keeps the Gaussians of its
// finest cells as moments in the block's sorted runs of cells (cell_runs.h: most sorted by the
// cells' Morton codes within the block, so the cells under any quadtree node are one contiguous
// run of each of its two sorted runs, the latest new cells in a short second run). Moments are
// sums of weighted end-points in coordinates relative to the cell's centre, in double: a cell's
// covariance comes out without the cancellation of map-frame moments. Not installed; included only
// by src/core/*.
#ifndef WAVOG_MAPPING_SRC_CORE_PAYLOADS_NDT_STORE_H_
#define WAVOG_MAPPING_SRC_CORE_PAYLOADS_NDT_STORE_H_

#include <cstdint>

#include "storage/cell_runs.h"

namespace wavog {
namespace detail {

/// The moments of one finest cell's end-points (weights w_i, offsets (x_i, y_i) from the centre).
struct NdtMoments {
  double w = 0.0;                          ///< sum w_i
  double sx = 0.0, sy = 0.0;               ///< sum w_i x_i, sum w_i y_i
  double sxx = 0.0, sxy = 0.0, syy = 0.0;  ///< sum w_i x_i^2, sum w_i x_i y_i, sum w_i y_i^2

  void scale(double f) {
    w *= f;
    sx *= f;
    sy *= f;
    sxx *= f;
    sxy *= f;
    syy *= f;
  }
  /// Adds the moments `m` of a cell whose centre lies at (ox, oy) from this one's origin (the
  /// parallel-axis shift).
  void addShifted(const NdtMoments& m, double ox, double oy) {
    w += m.w;
    sx += m.sx + m.w * ox;
    sy += m.sy + m.w * oy;
    sxx += m.sxx + 2.0 * ox * m.sx + m.w * ox * ox;
    sxy += m.sxy + ox * m.sy + oy * m.sx + m.w * ox * oy;
    syy += m.syy + 2.0 * oy * m.sy + m.w * oy * oy;
  }
  void add(double g, double x, double y) {
    w += g;
    sx += g * x;
    sy += g * y;
    sxx += g * x * x;
    sxy += g * x * y;
    syy += g * y * y;
  }
};

/// One finest cell holding a Gaussian: its Morton code within its block and its moments.
struct NdtEntry {
  std::uint32_t code = 0;
  NdtMoments m;

  bool live() const { return m.w > 0.0; }
  void kill() { m = NdtMoments{}; }
};

/// A block's Gaussians (cell_runs.h); a dropped one has weight 0.
using NdtCells = CellRuns<NdtEntry>;

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_PAYLOADS_NDT_STORE_H_
