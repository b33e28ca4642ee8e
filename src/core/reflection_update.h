// The update of the reflection map's hits by one scan (MapParams::reflection, reflection.cpp):
// the quadtree walk (Integrator<P, kNdt, true>, quadtree_update.h) lists the block's occupied
// cells with their log-odds before the scan, then HitBlockUpdate counts them, or under "forget"
// renews their ratio q = A / h (reflection_store.h). Free space costs nothing: misses are read
// from the occupancy. Not installed; included only by src/core/integrate*.cpp.
#ifndef WAVOG_MAPPING_SRC_CORE_REFLECTION_UPDATE_H_
#define WAVOG_MAPPING_SRC_CORE_REFLECTION_UPDATE_H_

#include <algorithm>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "map_impl.h"
#include "reflection_store.h"

namespace wavog {
namespace detail {

/// What a scan does to the hits: count, or (ratios) forget by a = 1 - g with a hit weighing g.
struct HitConsts {
  bool ratios = false;
  double a = 1.0, g = 0.0;
  ReflectionBasis basis;
};

/// The hits of one block for one scan: observations() is filled by the walk of the block, then
/// finish() applies them.
class HitBlockUpdate {
 public:
  HitBlockUpdate(const WaveletMap::Impl& impl, const HitConsts& c) : impl_(impl), c_(c) {}

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
      cells.ratios.upsertSorted(
          first, last, [this](HitRatio& e, const HitObservation& o) { renew(&e, o); },
          [this](const HitObservation& o) {
            HitRatio e;
            e.code = o.code;
            renew(&e, o);
            return e;
          });
      cells.ratios.mergeTailIfLong();
      // Sweep now and then, and soon when the block's hits stop (its cells then fade fast).
      cells.quiet = obs_.empty() ? cells.quiet + 1 : 0;
      if (++cells.scans >= kSweepScans || cells.quiet == kQuietScans) {
        cells.scans = 0;
        sweep(&cells.ratios, ix0, iy0);
      }
    } else {
      cells.counts.upsertSorted(
          first, last,
          [](HitCount& e, const HitObservation&) {
            if (e.n != std::numeric_limits<std::uint32_t>::max()) ++e.n;
          },
          [](const HitObservation& o) {
            HitCount e;
            e.code = o.code;
            e.n = 1;
            return e;
          });
      cells.counts.mergeTailIfLong();
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

  // Drops the ratios of cells whose hits have faded below kFadedHits.
  void sweep(CellRuns<HitRatio>* runs, std::int64_t ix0, std::int64_t iy0) {
    for (HitRatio& e : runs->entries) {
      if (!e.live()) continue;
      std::uint32_t lx, ly;
      mortonCell(e.code, &lx, &ly);
      const double before = impl_.read(0, ix0 + lx, iy0 + ly).average;
      if (c_.basis.hitsFromRatio(before, e.q) < kFadedHits) runs->drop(&e);
    }
    runs->removeDeadIfMany();
  }

  const WaveletMap::Impl& impl_;
  const HitConsts c_;
  std::vector<HitObservation> obs_;
};

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_REFLECTION_UPDATE_H_
