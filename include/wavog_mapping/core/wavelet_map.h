// WaveletMap: the WavOG occupancy map. Log-odds stored as Haar-wavelet quadtree blocks (one
// average per block, three details per node, a missing child is a uniform block) in a hash of
// blocks, so it grows without bound in every direction. Scans are integrated coarse to fine with
// the configured update policy; exponential forgetting uses lazy tags (ALGORITHM.md section 6).
// Frames: everything is in the map frame; cell (ix, iy) covers [ix, ix+1) x [iy, iy+1) *
// resolution. Thread-safety: a map is not synchronised. Concurrent const calls on one map are safe;
// any non-const call needs exclusive access to that map. integrate() keeps per-thread scratch
// buffers (a thread_local, reused from scan to scan), so maps used from different threads never
// share state, and each thread that integrates holds one scan's buffers for its lifetime. With
// MapParams::num_threads != 1 a map owns worker threads (made on its first scan that touches two
// blocks or more, kept until the map is destroyed, asleep between scans) that update the scan's
// blocks together with the calling thread, reading its prepared scan; integrate() returns when
// they are done, so the rules above are unchanged.
#ifndef WAVOG_MAPPING_CORE_WAVELET_MAP_H_
#define WAVOG_MAPPING_CORE_WAVELET_MAP_H_

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "wavog_mapping/core/limits.h"
#include "wavog_mapping/core/params.h"
#include "wavog_mapping/core/types.h"

namespace wavog {

/// What one integrate() call did. Per-scan calls never throw: a refused scan has status != kOk.
struct IntegrateStats {
  ScanStatus status = ScanStatus::kOk;
  std::uint32_t beams_hit = 0;        ///< beams with a return in [range_min, range_max)
  std::uint32_t beams_no_return = 0;  ///< +inf or >= range_max (REP 117)
  std::uint32_t beams_invalid = 0;    ///< NaN, -inf, <= 0, < range_min
  /// Readings below the scan's range limit but at or beyond the hard range limit
  /// (hardRangeLimit(), limits.h): taken as no returns, and counted in beams_no_return too.
  std::uint32_t beams_beyond_limit = 0;
  std::uint64_t nodes_visited = 0;   ///< tree nodes and finest cells visited
  std::uint32_t blocks_touched = 0;  ///< blocks classified as not U
  /// Finest cells within the scan's reach (the farthest E or O limit of its beams): every cell
  /// the scan changed lies in this box. Empty when status != kOk. With MapParams::region: clipped
  /// to the region's cells, empty when the scan reaches none of its blocks.
  CellBox touched;
  /// MapParams::region only: the scan (status kOk) reached none of the region's blocks, so
  /// nothing was walked or changed (its beams may then be left uncounted above).
  bool outside_region = false;
};

/// Size and work figures of a map.
struct MapStats {
  std::size_t blocks = 0;            ///< hashed blocks
  std::size_t nodes = 0;             ///< live quadtree nodes (each holds 3 details)
  std::size_t tiles = 0;             ///< dense 8 x 8 leaf tiles (storage/tile.h), of `nodes`
  std::size_t bytes = 0;             ///< bytes used: blocks, live node groups and the hash
  std::size_t reflection_bytes = 0;  ///< of them, the reflection layers' (MapParams::reflection)
  std::size_t ndt_cells = 0;         ///< finest cells holding a Gaussian (MapParams::ndt)
  std::size_t ndt_bytes = 0;         ///< of `bytes`, the Gaussians' (MapParams::ndt)
  std::size_t bytes_reserved = 0;    ///< bytes allocated: as `bytes`, but with every pool chunk
                                     ///< ever allocated (the high-water mark; chunks are not freed)
  std::uint64_t nodes_visited_last = 0;  ///< nodes visited by the last integrate()
  std::uint64_t observed_cells = 0;      ///< finest cells ever observed (only if requested)
};

/// How a coarse cell at scale s summarises its 4^s finest cells.
enum class Aggregation {
  kMean,  ///< the Haar average: mean log-odds of all finest cells (unobserved ones at the prior)
  kMax,   ///< the maximum log-odds over the observed finest cells (conservative, for planners)
};

/// A dense raster of one window at one scale, row-major (row = y, x fastest).
struct Raster {
  int scale = 0;                    ///< cells are 2^scale finest cells wide
  double cell_size = 0.0;           ///< metres per raster cell
  CellBox box;                      ///< window, in scale-s cell units
  std::vector<float> log_odds;      ///< per raster cell; the prior where nothing is observed
  std::vector<std::uint8_t> known;  ///< 1 if any finest cell under it was ever observed
  double originX() const { return static_cast<double>(box.min_x) * cell_size; }
  double originY() const { return static_cast<double>(box.min_y) * cell_size; }
};

/// Reflection probabilities of one window at one scale (WaveletMap::exportReflection), row-major:
/// p = hits / (hits + misses) summed over the finest cells under each raster cell; NaN where no
/// cell under it was observed. With the "max" policy (hits only) p is 1 where a beam ended, else 0.
struct ReflectionRaster {
  int scale = 0;
  double cell_size = 0.0;
  CellBox box;
  std::vector<float> p;
  double originX() const { return static_cast<double>(box.min_x) * cell_size; }
  double originY() const { return static_cast<double>(box.min_y) * cell_size; }
};

/// One normal-distribution cell (MapParams::ndt): the Gaussian of the beam end-points that fell
/// in a cell, weighted by the map's policy. At scale s it merges the finest cells' moments exactly.
struct NdtCell {
  std::int64_t ix = 0, iy = 0;        ///< the cell, in scale-s cell units
  double weight = 0.0;                ///< end-points it holds, as weighted by the policy
  double mean_x = 0.0, mean_y = 0.0;  ///< mean of the end-points (map frame, m)
  double cov_xx = 0.0, cov_xy = 0.0, cov_yy = 0.0;  ///< their covariance (m^2; 0 for one point)
  float log_odds = 0.0f;  ///< the cell's occupancy at that scale (Haar average)
};

/// The principal axes of a 2-D covariance: the standard deviations along its major and minor axes
/// (a round-off negative eigenvalue is taken as 0) and the major axis' angle from x (rad).
struct NdtAxes {
  double sigma_major = 0.0, sigma_minor = 0.0, yaw = 0.0;
};
NdtAxes principalAxes(double cov_xx, double cov_xy, double cov_yy);

/// The normal-distribution cells of one window at one scale (WaveletMap::exportNdt), sorted by
/// (iy, ix); only cells holding a Gaussian appear.
struct NdtLayer {
  int scale = 0;
  double cell_size = 0.0;
  CellBox box;
  std::vector<NdtCell> cells;
};

/// P(occ) of a log-odds: 1 / (1 + exp(-log_odds)), in [0, 1].
double probabilityFromLogOdds(float log_odds);
/// OccupancyGrid value of a log-odds: round(100 * P(occ)), in 0..100.
std::int8_t occupancyFromLogOdds(float log_odds);
/// OccupancyGrid values of a raster, same order: -1 where unknown, else occupancyFromLogOdds.
std::vector<std::int8_t> toOccupancyGrid(const Raster& raster);

/// How the log-odds of a layer become OccupancyGrid values. Trinary is ROS's map convention, what
/// map_server, amcl and costmap_2d's static layer read: P(occ) above occupied_thresh is 100, below
/// free_thresh 0, between (and never observed) -1. Graded: round(100 P(occ)), -1 never observed.
struct GridValues {
  bool trinary = true;
  double occupied_thresh = 0.65;  ///< map_server's default
  double free_thresh = 0.196;     ///< map_server's default
};
/// The OccupancyGrid value of one cell (known: observed at least once).
std::int8_t gridValue(float log_odds, bool known, const GridValues& values);
/// OccupancyGrid values of a raster under `values`, same order.
std::vector<std::int8_t> toOccupancyGrid(const Raster& raster, const GridValues& values);
/// OccupancyGrid values of reflection probabilities: -1 where NaN, else round(100 p).
std::vector<std::int8_t> toOccupancyGrid(const ReflectionRaster& raster);

/// A map file could not be written or read. what() names the file and the reason.
class MapIoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// exportScale was asked for more than kMaxReadoutCells raster cells (limits.h); nothing was
/// allocated. what() gives the window's size. Check readoutFits() first to avoid it.
class ReadoutTooLarge : public std::length_error {
 public:
  using std::length_error::length_error;
};

/// The payloads a map file holds besides the occupancy (WaveletMap::inspectFile): a map loading it
/// without MapParams::reflection / MapParams::ndt drops them, and a later save writes it without.
struct MapFileContents {
  bool reflection = false;  ///< a reflection map (hits, or hit and miss layers)
  bool ndt = false;         ///< normal-distribution cells
};

class WaveletMap {
 public:
  /// Throws std::invalid_argument naming every invalid parameter.
  explicit WaveletMap(const MapParams& params);
  ~WaveletMap();
  WaveletMap(WaveletMap&&) noexcept;
  WaveletMap& operator=(WaveletMap&&) noexcept;
  WaveletMap(const WaveletMap&) = delete;
  WaveletMap& operator=(const WaveletMap&) = delete;

  const MapParams& params() const;
  double resolution() const;
  /// The forgetting rate g a scan of `period` seconds applies (ScanView::period): gamma without
  /// forget_half_life (or with an unknown period), else 1 - 2^(-period / forget_half_life) with
  /// the exponent rounded to a multiple of forgetUnit(); 0 for policies other than "forget".
  double forgetRate(double period) const;
  /// forget_half_life only: the unit (in halvings) that each scan's exponent is rounded to.
  double forgetUnit() const;

  /// Integrates one scan taken from `sensor_pose` (map frame). Beams are classified per REP 117;
  /// every cell in the field of view is updated at most once. Readings at or beyond the hard
  /// range limit (hardRangeLimit(), limits.h) are no returns; a pose whose reach leaves the
  /// extent is refused (kOutOfExtent). Never throws.
  IntegrateStats integrate(const Pose2& sensor_pose, const ScanView& scan);

  /// Changes policy and sensor-model parameters at run time (grid and pruning stay). Pending lazy
  /// forgetting is applied first, so the stored map stays exact. Throws std::invalid_argument.
  void setPolicy(const PolicyParams& policy, const SensorModelParams& sensor);

  /// Log-odds of one finest cell (the prior if never observed) and whether it was observed.
  /// Cells outside the extent (limits.h) are never observed.
  float value(const CellIndex& cell) const;
  bool isObserved(const CellIndex& cell) const;
  /// Finest cell containing a map-frame point; indices are clamped to one cell beyond the extent
  /// (kCellIndexLimit), NaN to that cell too.
  CellIndex cellAt(double x, double y) const;

  /// Smallest box of scale-s cells holding every stored block; false when the map is empty.
  /// It always lies inside the extent (limits.h) but may be too large to read out: check it with
  /// readoutFits().
  bool bounds(int scale, CellBox* box) const;
  /// Box of scale-s cells covering the metric rectangle [min, max] (map frame), clamped to the
  /// extent (kCellIndexLimit finest cells; NaN bounds give an empty box).
  CellBox boxAround(double min_x, double min_y, double max_x, double max_y, int scale) const;
  /// Dense read-out of `window` at scale s in [0, block_levels]. Cost follows the stored nodes
  /// inside the window, not the whole map. Throws ReadoutTooLarge, allocating nothing, when the
  /// window has more than kMaxReadoutCells cells (readoutFits(window) is false).
  Raster exportScale(int scale, const CellBox& window, Aggregation aggregation) const;
  /// MapParams::reflection only (else throws std::logic_error): the reflection probabilities of
  /// `window` at scale s, exact at every scale (ratios of the Haar averages of hits and misses).
  /// Same limits as exportScale (throws ReadoutTooLarge).
  ReflectionRaster exportReflection(int scale, const CellBox& window) const;
  /// MapParams::reflection only: p of one finest cell (NaN if never observed).
  float reflection(const CellIndex& cell) const;
  /// MapParams::ndt only (else throws std::logic_error): the Gaussians of `window` at scale s in
  /// [0, block_levels], each merging the finest cells under it. Cost follows the stored Gaussians
  /// of the blocks the window meets; any window is taken (nothing dense is allocated).
  NdtLayer exportNdt(int scale, const CellBox& window) const;
  /// MapParams::ndt only: the Gaussian of one finest cell; false when it holds none.
  bool ndtCell(const CellIndex& cell, NdtCell* out) const;

  /// Forgets everything: the whole map back to never observed.
  void reset();
  /// Every finest cell whose centre lies in [min_x, max_x] x [min_y, max_y] (map frame) goes back
  /// to never observed. Any bounds are taken (infinite ones clear to the end of the extent; NaN
  /// or min > max clear nothing); the work follows the stored blocks. Returns the number of
  /// stored blocks the box met (changed or removed); 0 when nothing was cleared.
  std::size_t clearBox(double min_x, double min_y, double max_x, double max_y);

  /// Writes the map (versioned binary, CRC-32 checked) to `path` through a new temporary file in
  /// the same directory (created exclusively, never through a symlink), synced, then renamed over
  /// `path`: a crash or kill -9 leaves the old file or the complete new one. Throws MapIoError.
  void save(const std::string& path) const;
  /// Replaces the map by the one in `path`, a regular file (a directory, FIFO or device is refused
  /// at once, without blocking). A missing, truncated, corrupted or foreign file, one larger than
  /// its header's block count allows, one with a block outside the extent (kCellIndexLimit), or
  /// one with another resolution or block size, throws MapIoError naming the file and the reason,
  /// and leaves this map unchanged.
  void load(const std::string& path);
  /// What the map file at `path` holds: read with the checks of load() (any resolution and
  /// block_levels the parameters allow), so it throws MapIoError where load() would.
  static MapFileContents inspectFile(const std::string& path);

  /// Counts; `count_observed` also walks the tree to count observed cells (O(nodes)).
  MapStats stats(bool count_observed = false) const;

  /// Opaque storage, defined in src/core/storage/map_impl.h (named here so the core's sources
  /// can use it).
  struct Impl;

 private:
  friend struct MapAccess;  // tests inspect internals through this
  /// A reflection layer (reflection.cpp): parameters made by the core, not validated.
  struct LayerTag {};
  WaveletMap(const MapParams& params, LayerTag);
  /// load(), also saying what the file held (`contents` may be null; its ndt is read only by a
  /// map with MapParams::ndt, as inspectFile's).
  void load(const std::string& path, MapFileContents* contents);
  std::unique_ptr<Impl> impl_;
};

}  // namespace wavog

#endif  // WAVOG_MAPPING_CORE_WAVELET_MAP_H_
