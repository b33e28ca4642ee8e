// DenseGrid: the tuned dense 2D occupancy grid used as the near-limit reference in `make compare`.
// int16 fixed-point log-odds per cell, one integer DDA ray per beam, each cell updated at most once
// per scan (a per-cell scan stamp), hits win; the update costmap_2d and Cartographer do.
// Frames and units: map frame, metres, radians, log-odds; cell (ix, iy) covers
// [ix, ix+1) x [iy, iy+1) * resolution, like wavog::WaveletMap. Thread-safety: none; concurrent
// const calls are safe. ROS-free (std only); not part of wavog_core.
#ifndef WAVOG_MAPPING_BASELINE_DENSE_GRID_H_
#define WAVOG_MAPPING_BASELINE_DENSE_GRID_H_

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "wavog_mapping/core/types.h"

namespace wavog {
namespace baseline {

/// Parameters of the dense grid. The defaults equal MapParams::defaultsFor(PolicyType::kClamp)
/// and OctoMap's usual hit 0.7 / miss 0.4 / clamp 0.12..0.97.
struct DenseGridParams {
  /// Cell size (m), in (0.001, 100].
  double resolution = 0.05;
  /// Log-odds added to the end-point cell of a beam with a return, in (0, 7.9].
  double hit_log_odds = 0.85;
  /// Log-odds added to every other cell a beam crosses, in [-7.9, 0).
  double miss_log_odds = -0.4;
  /// Lower clamp bound (log-odds), in [-7.9, 0).
  double clamp_min_log_odds = -2.0;
  /// Upper clamp bound (log-odds), in (0, 7.9].
  double clamp_max_log_odds = 3.5;
  /// Readings at or beyond this range (m) are no return; 0 uses each scan's range_max; >= 0.
  double max_range_m = 0.0;
  /// No-return beams (+inf, >= range_max) mark free space up to this distance (m); 0: ignored.
  double no_return_clear_m = 0.0;
  /// Cells added on each side when the grid grows, at least; in [0, 1e5].
  int grow_margin_cells = 256;

  /// Every violated rule, one line each. Empty: valid.
  std::vector<std::string> validate() const;
};

/// What one integrate() call did.
struct DenseIntegrateStats {
  std::uint32_t beams_hit = 0;        ///< beams with a return in [range_min, max range)
  std::uint32_t beams_no_return = 0;  ///< +inf or >= max range (REP 117)
  std::uint32_t beams_invalid = 0;    ///< NaN, -inf, <= 0, < range_min
  std::uint64_t cells_updated = 0;    ///< cells whose value was updated (each at most once)
  bool rejected = false;              ///< bad pose or geometry: nothing was changed
};

class DenseGrid {
 public:
  /// Fixed-point scale: stored value = round(log-odds * kScale).
  static constexpr int kScale = 4096;
  /// Stored value of a never-observed cell.
  static constexpr std::int16_t kUnknown = INT16_MIN;

  /// Throws std::invalid_argument listing every invalid parameter.
  explicit DenseGrid(const DenseGridParams& params);
  DenseGrid(const DenseGrid&) = delete;
  DenseGrid& operator=(const DenseGrid&) = delete;
  DenseGrid(DenseGrid&&) = default;
  DenseGrid& operator=(DenseGrid&&) = default;

  const DenseGridParams& params() const { return params_; }

  /// Integrates one scan taken from `sensor_pose` (map frame): the end point cell of each beam with
  /// a return gets hit_log_odds, every other cell a beam (or a no-return clearing ray) crosses gets
  /// miss_log_odds; each cell at most once per scan, and a hit wins over a miss. Never throws;
  /// grows the grid to cover the scan.
  DenseIntegrateStats integrate(const Pose2& sensor_pose, const ScanView& scan);

  /// Makes the grid cover the cells of `box` now (contents kept), so that scans inside it never
  /// grow the grid: a pre-sized grid, as costmap_2d uses. An empty box does nothing.
  void reserve(const CellBox& box);

  /// Log-odds of a cell (0 if never observed) and whether it was observed.
  float value(const CellIndex& cell) const;
  bool isObserved(const CellIndex& cell) const;
  /// Cell containing a map-frame point.
  CellIndex cellAt(double x, double y) const;

  /// Cells held by the grid (observed or not), as a box of cell indices; empty before any scan.
  CellBox extent() const;
  /// Stored value of a cell inside extent() (kUnknown if never observed); row-major access for
  /// fast read-outs. Outside the extent: kUnknown.
  std::int16_t rawValue(std::int64_t ix, std::int64_t iy) const;
  /// Number of observed cells (O(cells held)).
  std::uint64_t countObserved() const;
  /// Bytes held: the cell array (value + stamp per cell) and the beam-direction cache.
  std::size_t bytes() const;

 private:
  /// One cell: fixed-point log-odds and the stamp of the last scan that updated it.
  struct Cell {
    std::int16_t value;
    std::uint16_t stamp;
  };

  /// Makes the grid cover cells [min_x, max_x] x [min_y, max_y] (inclusive), keeping the contents.
  void growToCover(std::int64_t min_x, std::int64_t min_y, std::int64_t max_x, std::int64_t max_y);
  /// Starts a new scan: next stamp; stamps wrap by clearing every cell's stamp.
  void nextStamp();
  /// Applies the miss update to every cell from `start` up to, not including, the cell of `end`.
  /// Points are in fixed-point sub-cell units relative to the grid origin. Returns cells updated.
  std::uint64_t traceFree(std::int64_t sx, std::int64_t sy, std::int64_t ex, std::int64_t ey);
  /// Rebuilds the beam direction table when the scan geometry changed.
  void cacheDirections(const ScanView& scan);

  DenseGridParams params_;
  double inv_resolution_;
  std::int16_t hit_;
  std::int16_t miss_;
  std::int16_t clamp_min_;
  std::int16_t clamp_max_;

  std::vector<Cell> cells_;    // row-major, width_ x height_
  std::int64_t origin_x_ = 0;  // cell index of cells_[0]
  std::int64_t origin_y_ = 0;
  std::int64_t width_ = 0;
  std::int64_t height_ = 0;
  std::uint16_t stamp_ = 0;

  // Beam directions in the sensor frame, cached per (angle_min, angle_increment, count).
  std::vector<double> dir_cos_;
  std::vector<double> dir_sin_;
  double cached_angle_min_ = 0.0;
  double cached_angle_increment_ = 0.0;
  // Per-scan scratch, reused across scans: end points in cells (map frame) and in sub-cell units
  // (grid frame), and what each beam does.
  std::vector<double> end_fx_;
  std::vector<double> end_fy_;
  std::vector<std::int64_t> end_x_;
  std::vector<std::int64_t> end_y_;
  std::vector<std::uint8_t> kind_;
};

}  // namespace baseline
}  // namespace wavog

#endif  // WAVOG_MAPPING_BASELINE_DENSE_GRID_H_
