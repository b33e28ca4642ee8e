// The hits of the reflection map (MapParams::reflection, reflection.cpp), kept per block for the
// finest cells a beam ended in (the occupied band) and nowhere else: a count of hits under the
// counting policies, and under "forget" the ratio q = A / h of the cell's weight of never having
// been observed (A, the product of its (1 - g) factors) to its hits h. Between two hits both
// decay by the same factors, so q stays as it was and free space is never touched: h is read back
// from the occupancy (reflection.cpp). Not installed; included only by src/core/*.
#ifndef WAVOG_MAPPING_SRC_CORE_PAYLOADS_REFLECTION_STORE_H_
#define WAVOG_MAPPING_SRC_CORE_PAYLOADS_REFLECTION_STORE_H_

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "storage/cell_runs.h"
#include "wavog_mapping/core/params.h"

namespace wavog {
namespace detail {

/// The hits of one cell under a counting policy (none, max, the clamps); 0 is no entry.
struct HitCount {
  std::uint32_t code = 0;
  std::uint32_t n = 0;

  bool live() const { return n != 0; }
  void kill() { n = 0; }
};

/// The hits of one cell under "forget": q = A / h >= 0; negative is no entry.
struct HitRatio {
  std::uint32_t code = 0;
  float q = -1.0f;

  bool live() const { return q >= 0.0f; }
  void kill() { q = -1.0f; }
};

/// The hits h and misses m of one hit cell under the clamp policies, whose total is bounded
/// (ReflectionBasis::bound), as they were when the cell's log-odds were `l` (after its last hit):
/// the misses since then are read from the occupancy (pairNow); a negative h is no entry.
struct HitPair {
  std::uint32_t code = 0;
  float h = -1.0f;
  float m = 0.0f;
  float l = 0.0f;

  bool live() const { return h >= 0.0f; }
  void kill() { h = -1.0f; }
};

/// One bit per finest cell of a block, set where one of its runs holds an entry (live or dead), so
/// that a scan's hit on a cell whose bit is clear adds an entry without searching the runs (most
/// hits of a moving scene are on new cells). The runs change elsewhere only by losing entries
/// (sweeps, clearBox), so that they are in step while their size is the one last recorded, and
/// else rebuilt.
class CellBits {
 public:
  template <typename Entry>
  bool inStep(const CellRuns<Entry>& runs) const {
    return &runs == static_cast<const void*>(of_) && runs.entries.size() == size_;
  }
  bool test(std::uint32_t code) const { return ((words_[code >> 6] >> (code & 63u)) & 1u) != 0; }
  void set(std::uint32_t code) { words_[code >> 6] |= std::uint64_t{1} << (code & 63u); }
  /// The bits of the entries of `runs`, in a block of 4^levels cells.
  template <typename Entry>
  void rebuild(const CellRuns<Entry>& runs, int levels) {
    words_.assign(std::max<std::size_t>(1, (std::size_t{1} << (2 * levels)) / 64), 0);
    for (const Entry& e : runs.entries) set(e.code);
    step(runs);
  }
  /// `runs`, after set() for each entry added to them, are in step.
  template <typename Entry>
  void step(const CellRuns<Entry>& runs) {
    of_ = &runs;
    size_ = runs.entries.size();
  }
  std::size_t bytes() const { return words_.capacity() * sizeof(std::uint64_t); }

 private:
  std::vector<std::uint64_t> words_;
  const void* of_ = nullptr;  // the runs they are in step with, at `size_` entries
  std::size_t size_ = 0;
};

/// A block's hits: `counts`, `ratios` or `pairs`, by the map's policy, with `bits` of the cells
/// with an entry. `scans`: integrations that met the block since its entries were last swept of
/// the cells whose hits have faded; `quiet`: the last of them in a row without a hit; `swept`: the
/// entries that sweep left (reflection_update.h).
struct HitCells {
  CellRuns<HitCount> counts;
  CellRuns<HitRatio> ratios;
  CellRuns<HitPair> pairs;
  CellBits bits;
  std::uint32_t scans = 0, quiet = 0;
  std::size_t swept = 0;  // entries the last sweep left

  bool empty() const { return counts.empty() && ratios.empty() && pairs.empty(); }
};

/// Hits under "forget" below which a cell's ratio is dropped (its h reads 0 from then on); under
/// the clamps, the share of its count below which a pair is dropped.
constexpr double kFadedHits = 1e-7;

/// The policies that bound a cell's count of hits and misses (ReflectionBasis::bound).
constexpr bool boundsCounts(PolicyType t) {
  return t == PolicyType::kClamp || t == PolicyType::kClampLower || t == PolicyType::kClampUpper;
}

/// The clamps' bound on a cell's count of hits and misses: the misses the occupancy's lower
/// bound holds, clamp_min / odd_emp ("clamp", "clamp_lower"); "clamp_upper", which has none,
/// counts without bound. A hit cell whose occupancy a miss takes to its empty bound (clamp_min)
/// forgets its hits: h = 0, m = the bound, what a cell never hit reads there.
inline double countBound(const MapParams& p) {
  if (p.policy.type == PolicyType::kClampUpper) return std::numeric_limits<double>::infinity();
  return p.policy.clamp_min / p.sensor.odd_emp;
}

/// The clamps: the occupancy's empty bound, at which a hit cell forgets its hits (clamp_min for
/// "clamp" and "clamp_lower"; none, -inf, for "clamp_upper").
inline double emptyBound(const MapParams& p) {
  if (p.policy.type == PolicyType::kClampUpper) return -std::numeric_limits<double>::infinity();
  return p.policy.clamp_min;
}

/// The clamps: the log-odds of a cell of log-odds `l` after a hit (clamp_max bounds them under
/// "clamp" and "clamp_upper").
inline double afterHit(const MapParams& p, double l) {
  const double up = l + p.sensor.odd_occ;
  return p.policy.type == PolicyType::kClampLower ? up : std::min(up, p.policy.clamp_max);
}

/// Log-odds above clamp_min within which a cell's occupancy counts as at its empty bound (float
/// round-off of the tree's coefficients; the clamps' reflection map resets the cell there).
constexpr double kAtEmptyBound = 1e-5;

/// The counts of a hit cell under the clamps.
struct PairCounts {
  double h = 0.0, m = 0.0;
  bool at_bound = false;  ///< the occupancy is at its empty bound: the hits are forgotten
};

/// Log-odds within which a hit cell reads as not updated since its pair was brought up to date
/// (the float round-off of reading it back through the tree's details is far below).
constexpr double kUnmoved = 1e-4;
/// The same relative to the cell's log-odds, above the empty bound: a pair keeps its log-odds as
/// a float e.l, set from the cell's double ones, whose round-off (half a float spacing, up to
/// |l| 2^-24) passes half a miss (odd_emp / 2, 0.2 by default) from |l| ~ 3.4e6 and then read as
/// misses, added again by every save and load. Up to four times that round-off a cell reads as not
/// updated; a true miss is lost only where |l| 2^-22 > |odd_emp| (1.7e6 by default), which a
/// clamp map reaches by updates only on the side it leaves unbounded ("clamp_lower" by millions of
/// hits, "clamp_upper" by millions of misses), and a file anywhere up to kMaxStoredLogOdds.
constexpr double kUnmovedRelative = 0x1p-22;

/// r^k for a whole number k: by squaring where 0 <= k < 2^32, a few multiplications for the
/// counts of misses a cell can take between its bounds (std::pow costs some hundred instructions).
inline double powCount(double r, double k) {
  if (!(k >= 0.0 && k < 4294967296.0)) return std::pow(r, k);
  auto e = static_cast<std::uint32_t>(k);
  double out = 1.0;
  for (; e != 0; e >>= 1, r *= r) {
    if ((e & 1u) != 0) out *= r;
  }
  return out;
}

/// The clamps: the counts of pair `e` once its cell reads log-odds `l`. Between two hits only
/// misses change a cell, each by odd_emp, until its empty bound (where the walk would have reset
/// it: h = 0, m = the bound), so that n = (l - e.l) / odd_emp misses came since e was brought up to
/// date; each added 1 to m and scaled h and m to keep h + m <= bound: the first ones that fit add
/// 1, the next one scales to the bound, each further one scales h by bound / (bound + 1). The
/// counts come as floats, as an entry holds them (a file's are read back exactly).
inline PairCounts pairNow(const HitPair& e, double l, double odd_emp, double bound,
                          double empty_bound) {
  const double h = e.h, m = e.m;
  const double moved = l - static_cast<double>(e.l);
  if (std::fabs(moved) <= kUnmoved) return {h, m, false};  // no miss since
  if (l <= empty_bound + kAtEmptyBound) return {0.0, static_cast<float>(bound), true};
  // Only the round-off of the float e.l at huge log-odds: no miss either.
  if (std::fabs(moved) <= kUnmovedRelative * std::fabs(l)) return {h, m, false};
  const double n = std::max(0.0, std::round(moved / odd_emp));
  // No whole miss (float round-off of a huge e.l in a file): the counts stand, above the bound
  // too, which only the next miss scales down.
  if (n == 0.0) return {h, m, false};
  const double room = bound - (h + m);  // misses that fit under the bound (inf without one)
  if (!(n > room)) return {h, static_cast<float>(m + n), false};
  const double fit = std::max(0.0, std::floor(room));
  const auto scaled = static_cast<float>(h * (bound / (h + m + fit + 1.0)) *
                                         powCount(bound / (bound + 1.0), n - fit - 1.0));
  return {scaled, static_cast<float>(bound - scaled), false};
}
/// pairNow() with the bound of map parameters `p`.
inline PairCounts pairNow(const HitPair& e, double l, const MapParams& p) {
  return pairNow(e, l, p.sensor.odd_emp, countBound(p), emptyBound(p));
}

/// What the occupancy of a cell says about its hits h and misses m when the map has applied one
/// policy with the same odd values and prior since it was empty (ALGORITHM.md; docs/algorithm.md):
/// "none" gives L = init + odd_occ h + odd_emp m, "forget" (prior 0) L = odd_occ h + odd_emp m with
/// h + m = 1 - A, A the cell's weight of never having been observed.
struct ReflectionBasis {
  PolicyType type = PolicyType::kNone;
  double odd_occ = 0.0, odd_emp = 0.0, init = 0.0;

  bool operator==(const ReflectionBasis& o) const {
    return type == o.type && odd_occ == o.odd_occ && odd_emp == o.odd_emp && init == o.init;
  }
  bool operator!=(const ReflectionBasis& o) const { return !(*this == o); }
  /// The misses of a cell (or the mean of a square's cells) of log-odds `l` and hits `h`.
  double misses(double l, double h) const { return (l - init - odd_occ * h) / odd_emp; }
  /// "forget": the hits of a cell of log-odds `l` and ratio q = A / h (solving the above).
  double hitsFromRatio(double l, float q) const {
    const double h = (l - odd_emp) / ((odd_occ - odd_emp) - odd_emp * static_cast<double>(q));
    return std::min(1.0, std::max(0.0, h));
  }
  /// The clamps: the misses of a cell of log-odds `l` that was never hit. Its log-odds are
  /// max(clamp_min, prior + odd_emp n) after n misses, so l / odd_emp is min(bound, m0 + n) with
  /// m0 = prior / odd_emp, the misses its prior stands for: exactly its bounded count.
  double missesOfUnhit(double l) const { return l / odd_emp; }
  /// "forget": A of a cell of log-odds `l` that was never hit (h = 0, m = 1 - A).
  double neverObservedWeight(double l) const {
    return std::min(1.0, std::max(0.0, 1.0 - l / odd_emp));
  }
};

/// One occupied (O) finest cell of a scan, as the quadtree walk met it: its Morton code within
/// its block and its log-odds before the scan.
struct HitObservation {
  std::uint32_t code;
  double before;
};

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_PAYLOADS_REFLECTION_STORE_H_
