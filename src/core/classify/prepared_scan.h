// The per-scan data of the integration: the scan's geometry, each beam's kind and E / U limits,
// the min / max table over beam intervals, the hit cells and the sector boundary directions
// (ALGORITHM.md section 3.1). One copy of each quantity: the squared limits are level 0 of the
// min / max table. Built once per scan by prepare(), read by the ScanClassifier.
// Not installed; included only by src/core/* and the core tests.
#ifndef WAVOG_MAPPING_SRC_CORE_CLASSIFY_PREPARED_SCAN_H_
#define WAVOG_MAPPING_SRC_CORE_CLASSIFY_PREPARED_SCAN_H_

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "classify/scan_numerics.h"
#include "classify/sector_table.h"
#include "wavog_mapping/core/params.h"
#include "wavog_mapping/core/types.h"

namespace wavog {
struct IntegrateStats;

namespace detail {

class WorkerPool;  // update/worker_pool.h

/// While it lives, PreparedScan::prepare() on this thread shares its per-beam work (endpoints,
/// thresholds, boundaries, the min / max tables) with the workers of `pool` (integrate.cpp: the
/// map's threads; nullptr: none). They only help: the result is the same with or without them.
class PrepareHelpers {
 public:
  explicit PrepareHelpers(WorkerPool* pool);
  ~PrepareHelpers();
  PrepareHelpers(const PrepareHelpers&) = delete;
  PrepareHelpers& operator=(const PrepareHelpers&) = delete;

 private:
  WorkerPool* previous_;
};

/// A beam per REP 117: no information, a return (hit), or a no-return that clears free space.
enum class BeamKind : std::uint8_t { kInvalid, kHit, kClear };

/// The exact leaf tests of one beam on a cell centre's squared distance d2 (see sqrtBelow):
/// E when d2 < e (-1: an invalid beam, never E), else O when d2 <= o (-1: not a hit, never O).
struct LeafTest {
  double e = -1.0;
  double o = -1.0;
};

/// The reasons the core refuses a whole scan before its reach is known (kEmpty, kBadGeometry,
/// kBadPose), or kOk. The extent is checked with the reach (reachInExtent).
ScanStatus checkScan(const Pose2& pose, const ScanView& scan);

/// The range limits of one scan's beams (m): no return at or beyond sensor_max, the given
/// limit (min of range_max and max_range) capped, like the no-return clearing distance, by the
/// hard limit (limits.h).
struct BeamLimits {
  double given = 0, sensor_max = 0, clear = 0, half_band = 0;
};
BeamLimits beamLimits(const MapParams& params, const ScanView& scan);

/// Whether every cell within the largest reach `limits` allow of `pose` lies inside the extent
/// (two cells of margin), so that each is an exact int64 and a distinct 32-bit block key.
bool reachInExtent(const Pose2& pose, const BeamLimits& limits, double resolution);

/// One scan, ready for classification. Beams are reordered by ascending bearing (inc > 0).
struct PreparedScan {
  /// Validates `scan` and `pose` and fills every field (buffers are reused between scans).
  /// Beam counts go to `st`. Anything but kOk leaves the fields unusable.
  ScanStatus prepare(const MapParams& params, const Pose2& pose, const ScanView& scan,
                     IntegrateStats* st);
  /// Releases the buffers when they were sized for more than kScratchKeepBeams beams (limits.h),
  /// so one absurd scan does not keep its memory; ordinary scans keep reusing theirs.
  void releaseIfLarge();

  double px = 0, py = 0, theta = 0;  ///< sensor pose (map frame)
  double amin = 0, inc = 0;          ///< beam j at bearing amin + j * inc (sensor frame), inc > 0
  double seam = 0;                   ///< bearings are normalised into [seam, seam + 2 pi)
  double res = 0;                    ///< cell size (m)
  int n = 0;                         ///< beams
  double reach = 0;                  ///< largest U limit over the valid beams (m)
  // Bearing constants of the fast beam lookup.
  double seam_map = 0;                  ///< theta + seam reduced to [-pi, pi): the seam, map frame
  double inv_inc = 0;                   ///< 1 / inc
  double t_seam = 0;                    ///< (seam - amin) / inc
  double fast_guard = 0;                ///< |t - (j + 1/2)| beyond which fastAtan2 gives lround(t)
  double cos_theta = 1, sin_theta = 0;  ///< rotate map-frame offsets into the sensor frame

  std::vector<BeamKind> kind;  ///< per beam
  std::vector<LeafTest> leaf;  ///< per beam: exact leaf thresholds; leaf[n]: outside (never E, O)
  std::vector<std::int64_t> hit_x, hit_y;  ///< per beam: the cell of its endpoint (hit beams)
  std::vector<double> end_x, end_y;        ///< per beam: its endpoint, map frame (hit beams)
  std::vector<std::uint64_t> hits;         ///< sorted cellKey()s of the hit endpoints
  std::vector<int> invalid_prefix;         ///< invalid_prefix[j] = invalid beams in [0, j)
  /// Min of the squared E limits and max of the squared U limits over [j, j + 2^k), level-major
  /// (n per level); level 0 holds each beam's own squared limits (squaredLimit; -1 for none).
  std::vector<double> min_e2, max_u2;
  std::vector<double> bnd_x, bnd_y;  ///< boundary k between sectors k-1 and k: unit direction
  SectorTable sectors;  ///< sector of a sensor-frame direction, kept while the geometry is
  /// Per beam: the hit cell's 4 x 4 group as groupKey() and its bit x + 4 y in the group (0
  /// for a beam without a hit), so a group gathers its hits without a branch.
  std::vector<std::uint32_t> hit_group, hit_bit;
  std::int64_t group_x0 = 0, group_y0 = 0;  ///< the sensor's 4 x 4 group (cells / 4, floored)

  /// Squared E and U limits of beam j.
  double e2(std::size_t j) const { return min_e2[j]; }
  double u2(std::size_t j) const { return max_u2[j]; }
  /// Min squared E limit / max squared U limit over beams [lo, hi] (lo <= hi), in O(1).
  double minE2(int lo, int hi) const {
    const int k = 31 - __builtin_clz(static_cast<unsigned>(hi - lo + 1));
    const std::size_t base = static_cast<std::size_t>(k) * static_cast<std::size_t>(n);
    return std::min(min_e2[base + static_cast<std::size_t>(lo)],
                    min_e2[base + static_cast<std::size_t>(hi - (1 << k) + 1)]);
  }
  double maxU2(int lo, int hi) const {
    const int k = 31 - __builtin_clz(static_cast<unsigned>(hi - lo + 1));
    const std::size_t base = static_cast<std::size_t>(k) * static_cast<std::size_t>(n);
    return std::max(max_u2[base + static_cast<std::size_t>(lo)],
                    max_u2[base + static_cast<std::size_t>(hi - (1 << k) + 1)]);
  }
  /// True if a beam in [lo, hi] is invalid.
  bool anyInvalid(int lo, int hi) const {
    return invalid_prefix[static_cast<std::size_t>(hi) + 1] >
           invalid_prefix[static_cast<std::size_t>(lo)];
  }
  /// True if beam j is a hit whose endpoint lies in cell (ix, iy).
  bool hitsCell(std::size_t j, std::int64_t ix, std::int64_t iy) const {
    return kind[j] == BeamKind::kHit && hit_x[j] == ix && hit_y[j] == iy;
  }

  /// The 4 x 4 group of cells holding cell (ix, iy) as 16 + 16 bits relative to the sensor's:
  /// distinct for every group within 2^17 cells of the sensor (the hard range limit is 2^16).
  std::uint32_t groupKey(std::int64_t ix, std::int64_t iy) const {
    const auto gx = static_cast<std::uint32_t>((ix >> 2) - group_x0) & 0xFFFFu;
    const auto gy = static_cast<std::uint32_t>((iy >> 2) - group_y0) & 0xFFFFu;
    return gx | (gy << 16);
  }
  /// The sensor-frame components of map-frame offset (dx, dy).
  double sensorX(double dx, double dy) const { return cos_theta * dx + sin_theta * dy; }
  double sensorY(double dx, double dy) const { return cos_theta * dy - sin_theta * dx; }
  /// The sector of map-frame offset (dx, dy) from the table (n: outside the fan), or kUnsure.
  /// The offset (0, 0) (the sensor exactly on a cell centre) has no direction: the reference
  /// takes its bearing as atan2(0, 0) = 0 in the map frame, -theta in the sensor frame, which the
  /// table (sensor frame, where (0, 0) lands in the bucket of bearing 0) cannot know: kUnsure,
  /// so that beamOf() decides it as the reference does (issue 42).
  std::int32_t tableSector(double dx, double dy) const {
    if (dx == 0.0 && dy == 0.0) return SectorTable::kUnsure;
    return sectors.sector(sensorX(dx, dy), sensorY(dx, dy));
  }
  static std::uint64_t cellKey(std::int64_t ix, std::int64_t iy) {
    return (static_cast<std::uint64_t>(ix + (std::int64_t{1} << 31)) << 32) ^
           static_cast<std::uint64_t>(iy + (std::int64_t{1} << 31));
  }
  /// A sensor-frame bearing normalised into [seam, seam + 2 pi).
  double normalise(double bearing) const {
    return bearing - kTwoPi * std::floor((bearing - seam) / kTwoPi);
  }
  /// A map-frame direction angle (from fastAtan2, in [-pi, pi]) as its sensor-frame bearing's
  /// offset past the seam, in [0, 2 pi). Within a few ulps of normalise() - seam.
  double offSeam(double map_angle) const {
    double v = map_angle - seam_map;
    if (v < 0.0) v += kTwoPi;
    if (v >= kTwoPi) v -= kTwoPi;
    return v;
  }

 private:
  /// releaseIfLarge() frees a pseudo-bearing table of more buckets (a beam step under 1e-3 rad).
  static constexpr std::size_t kKeepBuckets = 8192;
  /// Beams per piece of the shared per-beam work (a multiple of setBoundaries' anchor step).
  static constexpr std::size_t kChunkBeams = 64;
  /// What the beams of one piece counted (IntegrateStats), their hits and their reach.
  struct ChunkTally {
    std::uint32_t hit = 0, no_return = 0, beyond_limit = 0, invalid = 0;
    std::size_t hits = 0;  // hit keys, sorted, from hit_keys_[first beam]
    double reach = 0.0;
  };
  void setGeometry(const Pose2& pose, const ScanView& scan, double res);
  void sizeBuffers();
  void setBoundaries(std::size_t lo, std::size_t hi);  // boundaries [lo, hi)
  void setBeams(const BeamLimits& limits, double range_min, std::size_t lo, std::size_t hi,
                ChunkTally* tally);  // beams [lo, hi)
  /// The beams' sensor-frame unit vectors, kept while the geometry (n, amin, inc) is.
  void setUnits();
  /// min_e2 (empty) or max_u2, every level.
  void buildTable(const BeamLimits& limits, double range_min, bool empty);
  void mergeHits(std::size_t chunks);
  int tableLevels() const;  // levels of the tables for n beams

  std::vector<float> ranges_;            // work copy, in ascending bearing order
  std::vector<std::uint64_t> hit_keys_;  // per piece, from its first beam: its hit keys, sorted
  std::vector<ChunkTally> tallies_;      // per piece
  // mergeHits(): runs of sorted keys, [begin, end)
  std::vector<std::pair<std::size_t, std::size_t>> runs_;
  std::vector<double> unit_c_, unit_s_;  // cos / sin of amin + j inc
  int units_n_ = -1;                     // the geometry they hold
  double units_amin_ = 0, units_inc_ = 0;
  bool exact_ends_ = false;  // endpoints by the reference's cos / sin for every hit (NDT)
};

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_CLASSIFY_PREPARED_SCAN_H_
