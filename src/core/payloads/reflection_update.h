// The update of the reflection map's hits by one scan (MapParams::reflection, reflection.cpp):
// the quadtree walk (Integrator<P, kNdt, true>, quadtree_update.h) lists the block's occupied
// cells with their log-odds before the scan, then HitBlockUpdate counts them, under "forget"
// renews their ratio q = A / h, under the clamps brings their pairs h, m up to date and counts the
// hit (reflection_store.h). Free space costs nothing: misses are read from the occupancy.
// Not installed; included only by src/core/update/integrate*.cpp.
#ifndef WAVOG_MAPPING_SRC_CORE_PAYLOADS_REFLECTION_UPDATE_H_
#define WAVOG_MAPPING_SRC_CORE_PAYLOADS_REFLECTION_UPDATE_H_

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <type_traits>
#include <vector>

#include "storage/cell_reader.h"
#include "storage/map_impl.h"
#include "payloads/reflection_store.h"

namespace wavog {
namespace detail {

/// What a scan does to the hits: count, or (ratios) forget by a = 1 - g with a hit weighing g,
/// or (pairs) count hits and misses with their total bounded at `bound`, reset at the
/// occupancy's `empty_bound` (countBound, emptyBound).
struct HitConsts {
  bool ratios = false;
  bool pairs = false;
  double a = 1.0, g = 0.0;
  double bound = 0.0;
  double empty_bound = -std::numeric_limits<double>::infinity();
  ReflectionBasis basis;
};

/// The hits of one block for one scan: observations() is filled by the walk of the block, then
/// finish() applies them.
class HitBlockUpdate {
 public:
  HitBlockUpdate(const WaveletMap::Impl& impl, const HitConsts& c)
      : impl_(impl), c_(c), counted_misses_(impl.reflection_mode == ReflectionMode::kCounts) {}

  std::vector<HitObservation>* observations() { return &obs_; }

  /// Applies the observations of the block `b` (origin cell ix0, iy0) and clears them.
  void finish(Block& b, std::int64_t ix0, std::int64_t iy0) {
    if (obs_.empty() && !b.hits) return;
    if (!b.hits) b.hits = std::make_unique<HitCells>();
    HitCells& cells = *b.hits;
    // The walk lists the cells in Morton order already (children in q order).
    const auto by_code = [](const HitObservation& x, const HitObservation& y) {
      return x.code < y.code;
    };
    if (!std::is_sorted(obs_.begin(), obs_.end(), by_code)) {
      std::sort(obs_.begin(), obs_.end(), by_code);
    }
    const HitObservation* first = obs_.data();
    const HitObservation* last = first + obs_.size();
    if (c_.ratios) {
      upsert(
          &cells.ratios, &cells.bits, first, last,
          [this](HitRatio& e, const HitObservation& o) { renew(&e, o); },
          [this](const HitObservation& o) {
            HitRatio e;
            e.code = o.code;
            renew(&e, o);
            return e;
          });
      // Sweep now and then, and soon when the block's hits stop (its cells then fade fast).
      if (sweepDue(&cells, cells.ratios)) {
        sweep(b, &cells.ratios);
        cells.swept = cells.ratios.entries.size();
      }
    } else if (c_.pairs) {
      upsert(
          &cells.pairs, &cells.bits, first, last,
          [this, ix0, iy0](HitPair& e, const HitObservation& o) { hitPair(&e, o, ix0, iy0); },
          [this, ix0, iy0](const HitObservation& o) {
            HitPair e;
            e.code = o.code;
            hitPair(&e, o, ix0, iy0);
            return e;
          });
      if (sweepDue(&cells, cells.pairs)) {
        sweepPairs(b, &cells.pairs, ix0, iy0);
        cells.swept = cells.pairs.entries.size();
      }
    } else {
      upsert(
          &cells.counts, &cells.bits, first, last,
          [](HitCount& e, const HitObservation&) {
            if (e.n != std::numeric_limits<std::uint32_t>::max()) ++e.n;
          },
          [](const HitObservation& o) {
            HitCount e;
            e.code = o.code;
            e.n = 1;
            return e;
          });
    }
    obs_.clear();
  }

  /// Integrations of a block between two sweeps of its faded entries, and integrations in a row
  /// without a hit after which it is swept.
  static constexpr std::uint32_t kSweepScans = 1024, kQuietScans = 64;
  /// Pairs: entries a block may gain over twice those its last sweep left before it is swept
  /// again (the pairs of cells back at the occupancy's empty bound go only then).
  static constexpr std::size_t kPairSweepSlack = 64;

 private:
  // A hit on the cell of `o` (entry e, live or not): h <- a h + g, A <- a A, q = A / h.
  void renew(HitRatio* e, const HitObservation& o) const {
    double h = 0.0, never = 0.0;
    if (e->live()) {
      h = c_.basis.hitsFromRatio(o.before, e->q);
      never = static_cast<double>(e->q) * h;
    } else {
      never = c_.basis.neverObservedWeight(o.before);
    }
    h = c_.a * h + c_.g;
    e->q = static_cast<float>(std::min(1.0, c_.a * never) / h);
  }

  // Pairs: a hit on the cell of `o` (entry e, live or not): its counts brought up to date, h + 1,
  // the total bounded, as of its log-odds after the hit.
  void hitPair(HitPair* e, const HitObservation& o, std::int64_t ix0, std::int64_t iy0) const {
    // Without an entry, or at the empty bound, the cell reads as never hit.
    const PairCounts now =
        e->live() ? pairNow(*e, o.before, c_.basis.odd_emp, c_.bound, c_.empty_bound)
                  : PairCounts{0.0, std::max(0.0, impl_.unhitMisses(ix0, iy0, o.code, o.before)),
                               false};
    const double h = now.h + 1.0, m = now.m;
    const double f = std::min(1.0, c_.bound / (h + m));
    e->h = static_cast<float>(h * f);
    e->m = static_cast<float>(m * f);
    e->l = static_cast<float>(afterHit(impl_.params, o.before));
  }

  // Counts or ratios: upsertSorted() of [first, last) into `runs`, searching only the cells that
  // `bits` say have an entry.
  template <typename Entry, typename Update, typename Make>
  void upsert(CellRuns<Entry>* runs, CellBits* bits, const HitObservation* first,
              const HitObservation* last, Update update, Make make) {
    if (!bits->inStep(*runs)) bits->rebuild(*runs, impl_.levels);
    runs->upsertSorted(
        first, last, update,
        [&](const HitObservation& o) {
          bits->set(o.code);
          return make(o);
        },
        [bits](std::uint32_t code) { return bits->test(code); });
    bits->step(*runs);
    runs->mergeTailIfLong();
  }

  // Counts an integration of the block of `cells`; true when the faded entries of its `runs` are
  // due a sweep: every kSweepScans, soon when its hits stop (its cells then fade fast), and for
  // pairs when they have doubled since the last sweep (so each is swept a bounded number of times).
  template <typename Entry>
  bool sweepDue(HitCells* cells, const CellRuns<Entry>& runs) const {
    cells->quiet = obs_.empty() ? cells->quiet + 1 : 0;
    const bool grown =
        std::is_same_v<Entry, HitPair> && runs.entries.size() > 2 * cells->swept + kPairSweepSlack;
    if (++cells->scans < kSweepScans && cells->quiet != kQuietScans && !grown) return false;
    cells->scans = 0;
    return true;
  }
  // Pairs: drops the entries of cells back at the occupancy's empty bound (they read as never hit;
  // after a restart, kCounts, they keep h = 0 and the bound), and those whose hits have faded to a
  // kFadedHits share of their count and whose misses are those the cell reads without an entry (to
  // kFadedHits of the bound), so that the cell's counts change by less than that.
  void sweepPairs(const Block& b, CellRuns<HitPair>* runs, std::int64_t ix0, std::int64_t iy0) {
    BlockCellReader reader(impl_, b);
    for (HitPair& e : runs->entries) {
      if (!e.live()) continue;
      const double l = reader.average(e.code);
      const PairCounts now = pairNow(e, l, c_.basis.odd_emp, c_.bound, c_.empty_bound);
      if (now.at_bound && !counted_misses_) {
        runs->drop(&e);
        continue;
      }
      if (!(now.h <= kFadedHits * (now.h + now.m))) continue;
      const double unhit = impl_.unhitMisses(ix0, iy0, e.code, l);
      if (std::fabs(unhit - now.m) <= kFadedHits * std::max(1.0, now.m)) runs->drop(&e);
    }
    runs->removeDeadIfMany();
  }

  // Drops the ratios of cells whose hits have faded below kFadedHits.
  void sweep(const Block& b, CellRuns<HitRatio>* runs) {
    BlockCellReader reader(impl_, b);
    for (HitRatio& e : runs->entries) {
      if (!e.live()) continue;
      if (c_.basis.hitsFromRatio(reader.average(e.code), e.q) < kFadedHits) runs->drop(&e);
    }
    runs->removeDeadIfMany();
  }

  const WaveletMap::Impl& impl_;
  const HitConsts c_;
  const bool counted_misses_;  // the misses of cells never hit are a restart's layer (kCounts)
  std::vector<HitObservation> obs_;
};

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_PAYLOADS_REFLECTION_UPDATE_H_
