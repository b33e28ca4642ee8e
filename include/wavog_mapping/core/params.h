// Parameters of the core, as plain structs with defaults. validate() lists every violation;
// the core constructors throw std::invalid_argument with that list, so an invalid map cannot exist.
// Units: metres, radians, log-odds (natural log of P(occ)/P(emp)).
#ifndef WAVOG_MAPPING_CORE_PARAMS_H_
#define WAVOG_MAPPING_CORE_PARAMS_H_

#include <cstdint>
#include <string>
#include <vector>

namespace wavog {

/// Update policy of a map (paper section 1.3). Names are the configuration strings.
enum class PolicyType {
  kNone,        ///< "none": additive Bayesian fusion, unbounded (eq. 1.2)
  kMax,         ///< "max": odd_t = max(odd_{t-1}, odd(z)) (eq. 1.4)
  kClamp,       ///< "clamp": additive, clamped to [clamp_min, clamp_max] (eq. 1.5)
  kForget,      ///< "forget": exponential forgetting odd_t = (1-g) odd_{t-1} + g odd(z) (eq. 1.6)
  kClampLower,  ///< "clamp_lower": additive, lower bound only (section 1.3.5)
  kClampUpper,  ///< "clamp_upper": additive, upper bound only (section 1.3.5)
};

/// Value of never-observed cells (the map's prior).
enum class InitValue {
  kUnknown,     ///< "unknown": log-odds 0 (P = 0.5)
  kEmptyBound,  ///< "empty_bound": the policy's empty bound (clamp_min, or odd_emp), best
                ///< compression
};

/// Configuration name <-> enum. fromString returns false on an unknown name.
const char* toString(PolicyType type);
const char* toString(InitValue init);
bool fromString(const std::string& name, PolicyType* type);
bool fromString(const std::string& name, InitValue* init);

/// Geometry of the grid.
struct GridParams {
  /// Finest cell size (m), in (0.001, 100].
  double resolution = 0.05;
  /// Levels of one hashed quadtree block: a block covers 2^block_levels cells per side, in [2, 12].
  int block_levels = 9;
};

/// Three-valued inverse sensor model (ALGORITHM.md sections 3-4): E / O / U per cell.
struct SensorModelParams {
  /// Log-odds added (or, with forgetting, approached) in the occupied band, > 0. The default is
  /// the "forget" policy's (its fixed point, ALGORITHM.md section 4); the other policies'
  /// default is kAdditiveOddOcc.
  double odd_occ = 3.5;
  /// Log-odds added (or, with forgetting, approached) in free space, < 0. Default: as odd_occ;
  /// the other policies' default is kAdditiveOddEmp.
  double odd_emp = -2.0;
  /// Defaults of odd_occ / odd_emp for every policy but "forget": OctoMap's usual hit 0.7 /
  /// miss 0.4 as log-odds.
  static constexpr double kAdditiveOddOcc = 0.85;
  static constexpr double kAdditiveOddEmp = -0.4;
  /// Width of the occupied band around a hit (m), >= 0; 0 means one cell (the resolution).
  double band_width = 0.0;
  /// Readings beyond this range (m) count as no return; 0 uses each scan's range_max; >= 0.
  double max_range = 0.0;
  /// No-return beams (+inf, >= range_max) clear free space up to this distance (m); 0: not at
  /// all; >= 0.
  double no_return_clear = 0.0;
};

/// Update policy and its parameters (paper section 1.3).
struct PolicyParams {
  /// The policy applied to E and O cells; U cells are never touched.
  PolicyType type = PolicyType::kForget;
  /// Forgetting rate gamma of eq. 1.6, in (0, 1]; used by "forget" only (paper: 0.3 at 10 Hz).
  /// With forget_half_life, only for scans whose period is unknown.
  double gamma = 0.3;
  /// "forget" only: half-life (s) of what a cell remembers while it is observed, in [0, 1e6];
  /// 0 = off (each scan forgets by gamma, whatever its rate). A scan of period dt
  /// (ScanView::period) then forgets by g = 1 - 2^(-dt / forget_half_life), so that lasers of any
  /// rate forget at the same rate per second. The exponent dt / forget_half_life of each scan is
  /// rounded to a multiple of the map's forgetting unit (WaveletMap::forgetUnit(): 2^-11 with
  /// the default pruning up to 0.8 s, finer beyond, so that a 25 ms scan counts 64 units or
  /// more), at least one unit (a scan always forgets), and capped where a subtree becomes
  /// negligible.
  double forget_half_life = 0.0;
  /// Lower clamp bound (log-odds), < 0; used by "clamp" and "clamp_lower".
  double clamp_min = -2.0;
  /// Upper clamp bound (log-odds), > 0; used by "clamp" and "clamp_upper".
  double clamp_max = 3.5;
  /// Value of never-observed cells.
  InitValue init = InitValue::kUnknown;
};

/// The blocks a map integrates into (a region shard of a fleet, docs/fleet.md): block (bx, by)
/// covers the finest cells [bx 2^block_levels, (bx + 1) 2^block_levels) x [by ..., ...); the
/// region holds min_bx <= bx < max_bx, min_by <= by < max_by. A scan still integrates exactly as
/// in a map of every block, but only into these blocks; one that reaches none of them costs its
/// preparation only. Every cell of a block depends only on the scans that reach that block, so
/// maps of disjoint regions fed the same scans hold, together, the cells of one map of all.
struct BlockRegion {
  bool all = true;  ///< every block (the default); the bounds below are then unused
  /// Block indices, min < max on each axis, inside the extent (limits.h): |bx| and |by| at most
  /// kCellIndexLimit >> block_levels.
  std::int64_t min_bx = 0, min_by = 0, max_bx = 0, max_by = 0;
  bool contains(std::int64_t bx, std::int64_t by) const {
    return all || (bx >= min_bx && bx < max_bx && by >= min_by && by < max_by);
  }
};

/// Everything a map needs.
struct MapParams {
  GridParams grid;
  SensorModelParams sensor;
  PolicyParams policy;
  /// Detail threshold tau (log-odds) for online pruning, in [0, 1]. 0 is lossless up to float
  /// round-off (details under 1e-6 are dropped); otherwise each cell's error from one pruning is
  /// at most 1.25 * tau * block_levels (ALGORITHM.md section 2.4).
  double prune_threshold = 0.0;
  /// Forgetting only: a FREE_OR_UNKNOWN uniform block is left alone when the E update would move
  /// it by at most this much (log-odds), in [0, 1]; 0 is exact. Error bound: skip_tolerance/gamma.
  double skip_tolerance = 0.0;
  /// Forgetting only: use lazy tags on fully-empty nodes (ALGORITHM.md section 6). false applies
  /// the forgetting eagerly to every stored detail (slow; for benchmarks and tests).
  bool lazy_forgetting = true;
  /// Threads that update one scan's blocks: the calling thread and num_threads - 1 workers that
  /// live as long as the map; 0: one per core. In [0, 256]. The map is bit-identical for every
  /// value; block selection and creation, and scans with one touched block, stay serial.
  int num_threads = 1;
  /// Also keep a reflection probability map (paper section 1.2.2, eq. 1.3): per finest cell the
  /// beams that ended in it (hits, the occupied band) and that crossed it (misses, E cells), under
  /// the map's policy: "none" counts, "forget" forgets both by gamma (h <- (1-g) h + g [hit],
  /// m <- (1-g) m + g [miss], from h = m = 0, or m = 1 with the empty_bound prior, as the
  /// occupancy starts at its empty bound), "max" counts hits only (the paper's compression), and
  /// the clamp policies bound a cell's count, not its hits and misses apart (which would bias p,
  /// paper section 1.3.3): they count, and scale both down to keep h + m <= clamp_min / odd_emp
  /// (the misses the occupancy's lower bound holds; 5 with the defaults: p is that window's
  /// ratio), and a hit cell whose occupancy a miss takes to clamp_min forgets its hits (h = 0, as
  /// a cell never hit reads there); cells start with prior / odd_emp misses; "clamp_upper", with no
  /// lower bound, counts without bound. The misses of cells never hit are read from the
  /// occupancy (and under "none" and "forget" those of every cell), so free space costs nothing
  /// more; the clamps' hit cells are counted as the walk crosses them. A change of the policy,
  /// its odd values or the prior (setPolicy, or a file built under other ones) restarts it from no
  /// counts. Off by default: maps, speed and files are then those without it.
  bool reflection = false;
  /// Also keep normal-distribution cells (paper section 1.2.3, Biber's NDT): per finest cell the
  /// weight, mean and covariance of the beam end-points that fell in it, with the map's policy
  /// applied to the weight: "none" and "max" sum the end-points, "forget" weighs the old
  /// moments by (1-g) at every observation of the cell (E or O) and each new end-point by g,
  /// "clamp" and "clamp_upper" cap the weight at ndt_max_weight by scaling the old moments down
  /// (a window of the latest end-points), "clamp_lower" sums. Coarse scales merge their cells'
  /// moments exactly. Off by default: maps, speed and files are then those without it.
  bool ndt = false;
  /// ndt: a Gaussian worth fewer end-points than this is dropped, in [0, 1e6]. The floor is in
  /// the end-points of the scan that changes the cell: ndt_min_weight times the weight it gives
  /// an end-point (1, or g under "forget", whose weights are normalised like its occupancy).
  /// So with ndt_min_weight <= 1 every end-point makes a Gaussian under every policy, half-life
  /// and scan rate; under "forget" a Gaussian of one end-point then lasts
  /// log2(1 / ndt_min_weight) half-lives of observation (6.6 by default; by gamma 0.3 it is
  /// dropped at the 13th scan),
  /// one of a cell hit every scan (1 / g end-points' worth) log2(1 / (g ndt_min_weight)). Over 1,
  /// a cell keeps a Gaussian only when one scan puts at least that many end-points in it.
  double ndt_min_weight = 0.01;
  /// ndt with "clamp" / "clamp_upper": the largest weight of a cell, in [1, 1e9].
  double ndt_max_weight = 100.0;
  /// The blocks this map integrates into (default: all). Kept by setPolicy().
  BlockRegion region;

  /// Every violated rule, one line each, naming the parameter and its valid range. Empty: valid.
  std::vector<std::string> validate() const;

  /// Valid combinations under which an option silently does (almost) nothing, one line each
  /// naming the parameters and their values (the node and wavog_offline warn with them at
  /// start-up). Empty: none.
  std::vector<std::string> warnings() const;

  /// The defaults for a policy: the field initialisers above (the "forget" policy's), with
  /// type = `type` and, for every other policy, odd_occ / odd_emp = kAdditiveOddOcc /
  /// kAdditiveOddEmp.
  static MapParams defaultsFor(PolicyType type);

  /// Log-odds of a never-observed cell under these parameters.
  double initValue() const;
};

/// Throws std::invalid_argument listing every violation of `params` (does nothing when valid).
void throwIfInvalid(const MapParams& params);

}  // namespace wavog

#endif  // WAVOG_MAPPING_CORE_PARAMS_H_
