// The update of the reflection map's hits by one scan (MapParams::reflection, reflection.cpp):
// the quadtree walk (Integrator<P, kNdt, true>, quadtree_update.h) lists the block's occupied
// cells with their log-odds before the scan, then HitBlockUpdate counts them, or under "forget"
// renews their ratio q = A / h (reflection_store.h). Free space costs nothing: misses are read
// from the occupancy. Under the clamps the walk also counts a miss on the hit cells it finds in
// free space (their pairs h, m; the total bounded), met by a cursor in code order.
// Not installed; included only by src/core/integrate*.cpp.
#ifndef WAVOG_MAPPING_SRC_CORE_REFLECTION_UPDATE_H_
#define WAVOG_MAPPING_SRC_CORE_REFLECTION_UPDATE_H_

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "cell_reader.h"
#include "map_impl.h"
#include "reflection_store.h"
#include "scan_classifier.h"

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
  HitBlockUpdate(const WaveletMap::Impl& impl, const ScanClassifier& cls, const HitConsts& c)
      : impl_(impl),
        cls_(cls),
        c_(c),
        bound_(static_cast<float>(c.bound)),
        counted_misses_(impl.reflection_mode == ReflectionMode::kCounts) {}

  std::vector<HitObservation>* observations() { return &obs_; }

  /// Pairs: starts block (origin cell ix0, iy0), whose walk then hands the squares and cells it
  /// finds E to missRange(), missObservedRange() and visitCells(), in code order (no entry is
  /// added or moved until finish()).
  void begin(Block& b, std::int64_t ix0, std::int64_t iy0) {
    ix0_ = ix0;
    iy0_ = iy0;
    runs_ = b.hits ? &b.hits->pairs : nullptr;
    ahead_ = end_ = nullptr;
    if (runs_ != nullptr) {
      runs_->mergeTail();  // one run for the cursor: the last scan's new cells merged in
      ahead_ = runs_->entries.data();
      end_ = ahead_ + runs_->entries.size();
    }
    next_ = ahead_ != end_ ? ahead_->code : ~0u;
  }
  /// Pairs: every cell of codes [code, code + 4^level) is E, of log-odds `after` after the scan.
  void missRange(std::uint32_t code, int level, double after) {
    inRange(code, code + (1u << (2 * level)), [&](HitPair* x) { miss(x, after); });
  }
  /// Pairs: the cells of codes [code, code + 4^level) (a square classified as `box`, of log-odds
  /// `l`) that are E.
  void missObservedRange(std::uint32_t code, int level, const SquareInfo& box, double l) {
    inRange(code, code + (1u << (2 * level)), [&](HitPair* x) {
      if (!x->live()) return;
      std::uint32_t lx, ly;
      mortonCell(x->code, &lx, &ly);
      if (cls_.classifyCell(ix0_ + lx, iy0_ + ly, box) == CellClass::kEmpty) miss(x, l);
    });
  }
  /// Pairs: the 4 cells of codes [code, code + 4), cell q E by bit q of `empty` and O by bit q of
  /// `occupied`, of log-odds c[q] before the scan and c[q] + delta[q] after it. The hits of those
  /// O cells that have an entry (live or dead) are counted here; returns their bits (the others
  /// are new cells, for finish()).
  std::uint32_t visitCells(std::uint32_t code, std::uint32_t empty, std::uint32_t occupied,
                           const std::array<double, 4>& c, const std::array<double, 4>& delta) {
    std::uint32_t counted = 0;
    inRange(code, code + 4, [&](HitPair* x) {
      const unsigned q = x->code & 3u;
      if ((occupied >> q) & 1u) {
        hit(x, c[q]);
        counted |= 1u << q;
      } else {
        missIf(x, (empty >> q) & 1u, c[q] + delta[q]);
      }
    });
    return counted;
  }
  /// Pairs: the scan crosses the cell of entry x (E), whose log-odds are `after` after the scan
  /// (NaN if not known). A cell the miss takes to the occupancy's empty bound forgets its hits.
  void miss(HitPair* x, double after) { missIf(x, true, after); }
  /// Pairs: miss(x, after) if `empty`, else nothing; without a branch on `empty` but where the
  /// miss takes the cell to the empty bound (the walk's finest cells, whose classes the branch
  /// predictor cannot guess).
  void missIf(HitPair* x, bool empty, double after) {
    const bool apply = empty && x->live();
    if (apply && after <= c_.empty_bound + kAtEmptyBound) {
      // At the occupancy's empty bound: no hits, a full count of misses, which is what the cell
      // reads without an entry (l / odd_emp = bound) unless the misses are a restart's layer.
      if (!counted_misses_) {
        runs_->drop(x);
      } else {
        x->h = 0.0f;
        x->m = bound_;
      }
      return;
    }
    // m + 1, then both scaled to keep h + m <= bound (h + m <= bound held before, so an entry
    // left alone scales by 1).
    const float h = x->h, m = x->m + (apply ? 1.0f : 0.0f);
    const float f = apply ? std::min(1.0f, bound_ / (h + m)) : 1.0f;
    x->h = h * f;
    x->m = m * f;
  }

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
      if (sweepDue(&cells)) sweep(b, &cells.ratios);
    } else if (c_.pairs) {
      // The walk counted the cells with an entry (visitCells): these are new.
      cells.pairs.insertNewSorted(first, last, [this, ix0, iy0](const HitObservation& o) {
        HitPair e;
        e.code = o.code;
        e.h = 1.0f;
        e.m = static_cast<float>(unhitMisses(o.code, ix0, iy0, o.before));
        bound(&e);
        return e;
      });
      cells.pairs.removeDeadIfMany();  // the walk's drops
      if (sweepDue(&cells)) sweepPairs(b, &cells.pairs, ix0, iy0);
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

  /// Integrations of a block between two sweeps of its faded ratios, and integrations in a row
  /// without a hit after which it is swept.
  static constexpr std::uint32_t kSweepScans = 1024, kQuietScans = 64;

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

  // Pairs: f(x) on the entries of codes [c0, c1), from where the last range ended (ranges come
  // in ascending order).
  template <typename F>
  void inRange(std::uint32_t c0, std::uint32_t c1, F f) {
    // Most ranges hold no hit cell: one test.
    if (next_ >= c1) return;
    // (The cursor is mostly at c0 already: gallop only past cells of squares not visited.)
    if (next_ < c0) ahead_ = gallop(ahead_, end_, c0);
    for (; ahead_ != end_ && ahead_->code < c1; ++ahead_) f(ahead_);
    next_ = ahead_ != end_ ? ahead_->code : ~0u;
  }
  // Pairs: a hit on the cell of entry x (live or dead), of log-odds `before` before the scan.
  void hit(HitPair* x, double before) {
    if (!x->live()) {
      x->h = 0.0f;
      x->m = static_cast<float>(unhitMisses(x->code, ix0_, iy0_, before));
      --runs_->dead;
    }
    x->h += 1.0f;
    bound(x);
  }
  // Pairs: the total of hits and misses bounded, keeping their ratio.
  void bound(HitPair* x) const {
    const float f = std::min(1.0f, bound_ / (x->h + x->m));
    x->h *= f;
    x->m *= f;
  }
  // Pairs: the misses of the cell of `code` (log-odds `l`) as if it were never hit, at least 0
  // (the occupancy's float round-off may leave a hair above the prior).
  double unhitMisses(std::uint32_t code, std::int64_t ix0, std::int64_t iy0, double l) const {
    std::uint32_t lx, ly;
    mortonCell(code, &lx, &ly);
    return std::max(0.0, impl_.unhitMisses(ix0 + lx, iy0 + ly, l));
  }
  // Counts an integration of the block of `cells`; true when its faded entries are due a sweep:
  // every kSweepScans, and soon when its hits stop (its cells then fade fast).
  bool sweepDue(HitCells* cells) const {
    cells->quiet = obs_.empty() ? cells->quiet + 1 : 0;
    if (++cells->scans < kSweepScans && cells->quiet != kQuietScans) return false;
    cells->scans = 0;
    return true;
  }
  // Pairs: drops the entries whose hits have faded to a kFadedHits share of their count and whose
  // misses are those the cell reads without an entry (to kFadedHits of the bound), so that the
  // cell's counts change by less than that.
  void sweepPairs(const Block& b, CellRuns<HitPair>* runs, std::int64_t ix0, std::int64_t iy0) {
    BlockCellReader reader(impl_, b);
    for (HitPair& e : runs->entries) {
      if (!e.live()) continue;
      const double h = e.h, m = e.m;
      if (!(h <= kFadedHits * (h + m))) continue;
      std::uint32_t lx, ly;
      mortonCell(e.code, &lx, &ly);
      const std::int64_t ix = ix0 + lx, iy = iy0 + ly;
      const double unhit =
          impl_.unhitMisses(ix, iy, counted_misses_ ? 0.0 : reader.average(e.code));
      if (std::fabs(unhit - m) <= kFadedHits * std::max(1.0, m)) runs->drop(&e);
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
  const ScanClassifier& cls_;
  const HitConsts c_;
  const float bound_;          // c_.bound
  const bool counted_misses_;  // the misses of cells never hit are a restart's layer (kCounts)
  std::vector<HitObservation> obs_;
  std::int64_t ix0_ = 0, iy0_ = 0;     // pairs: the block begin() started
  CellRuns<HitPair>* runs_ = nullptr;  // and its entries
  HitPair* ahead_ = nullptr;           // the first the walk has not passed yet (its cursor)
  HitPair* end_ = nullptr;             // and their end
  std::uint32_t next_ = ~0u;           // the cursor's code (~0u at the end)
};

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_REFLECTION_UPDATE_H_
