// The update of normal-distribution cells by one scan (MapParams::ndt): the scan's end-points
// grouped by block (NdtScanPoints), and per block (NdtBlockUpdate) the policy on the Gaussians:
// the quadtree walk of the block (quadtree_update.h) carries the span of the entries under each
// square it visits and forgets those the scan observes (U squares skip theirs, E squares forget
// all of theirs, finest cells by their class), then the new end-points are added. Not installed;
// included only by src/core/update/integrate*.cpp.
#ifndef WAVOG_MAPPING_SRC_CORE_PAYLOADS_NDT_UPDATE_H_
#define WAVOG_MAPPING_SRC_CORE_PAYLOADS_NDT_UPDATE_H_

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "storage/block_hash.h"
#include "payloads/ndt_store.h"
#include "classify/scan_classifier.h"

namespace wavog {
namespace detail {

/// One end-point of a scan: its block, its cell's Morton code there, its offset from the cell's
/// centre (m), its beam (the order of additions).
struct NdtPoint {
  std::uint64_t block;
  std::uint32_t code;
  std::uint32_t beam;
  double x, y;
};

/// The end-points of one scan, sorted by block, cell and beam.
class NdtScanPoints {
 public:
  void build(const PreparedScan& ps, int levels) {
    points_.clear();
    const auto n = static_cast<std::size_t>(ps.n);
    const std::int64_t mask = (std::int64_t{1} << levels) - 1;
    for (std::size_t j = 0; j < n; ++j) {
      if (ps.kind[j] != BeamKind::kHit) continue;
      const double ex = ps.end_x[j], ey = ps.end_y[j];
      const std::int64_t ix = ps.hit_x[j], iy = ps.hit_y[j];
      NdtPoint p;
      p.block = blockKey(floorShift(ix, levels), floorShift(iy, levels));
      p.code =
          mortonCode(static_cast<std::uint32_t>(ix & mask), static_cast<std::uint32_t>(iy & mask));
      p.beam = static_cast<std::uint32_t>(j);
      // In its cell by construction: far from the origin the subtraction's round-off could put
      // it beyond the half cell by an ulp of the coordinate, moments a file may not hold.
      const double h = 0.5 * ps.res;
      p.x = std::clamp(ex - (static_cast<double>(ix) + 0.5) * ps.res, -h, h);
      p.y = std::clamp(ey - (static_cast<double>(iy) + 0.5) * ps.res, -h, h);
      points_.push_back(p);
    }
    std::sort(points_.begin(), points_.end(), [](const NdtPoint& a, const NdtPoint& b) {
      if (a.block != b.block) return a.block < b.block;
      if (a.code != b.code) return a.code < b.code;
      return a.beam < b.beam;
    });
  }
  /// The points of block `key`: [*first, *last).
  void inBlock(std::uint64_t key, const NdtPoint** first, const NdtPoint** last) const {
    const auto lo =
        std::lower_bound(points_.begin(), points_.end(), key,
                         [](const NdtPoint& p, std::uint64_t k) { return p.block < k; });
    auto hi = lo;
    while (hi != points_.end() && hi->block == key) ++hi;
    *first = points_.data() + (lo - points_.begin());
    *last = points_.data() + (hi - points_.begin());
  }

 private:
  std::vector<NdtPoint> points_;
};

/// The Gaussians of a block under one square (cell_runs.h).
using NdtSpan = CellSpan<NdtEntry>;

/// The policy on the Gaussians for one scan: an observed cell's moments times `a`, each new
/// end-point weighing `g`, weights capped at `cap`, cells under `min_weight` dropped (the map's
/// ndt_min_weight times g: a floor in this scan's end-points).
struct NdtConsts {
  double a = 1.0;
  double g = 1.0;
  double cap = std::numeric_limits<double>::infinity();
  double min_weight = 0.0;

  /// True when an observation changes a Gaussian (the walk has to find the observed ones).
  bool forgets() const { return a != 1.0; }
};

/// The update of one block's Gaussians by a scan, in three steps: begin() makes the cells of the
/// scan's end-points (empty) and gives the span of all entries; the quadtree walk
/// (Integrator<P, true>, quadtree_update.h) calls forget() on every entry whose cell the scan
/// observes (only when NdtConsts::forgets()); finish() adds the end-points, caps the
/// weights and drops what is under the threshold.
class NdtBlockUpdate {
 public:
  NdtBlockUpdate(const ScanClassifier& cls, const NdtConsts& c) : cls_(cls), c_(c) {}

  /// Starts block (origin cell ix0, iy0) with its end-points [first, last); returns the span of
  /// its entries.
  NdtSpan begin(NdtCells& cells, std::int64_t ix0, std::int64_t iy0, const NdtPoint* first,
                const NdtPoint* last) {
    cells_ = &cells;
    ix0_ = ix0;
    iy0_ = iy0;
    first_ = first;
    last_ = last;
    low_.clear();
    for (const NdtPoint* p = first; p != last; ++p) {
      if (p == first || p->code != p[-1].code) cells.findOrInsert(p->code);
    }
    cells.mergeTailIfLong();
    // No entry is added or moved from here to finish().
    base_ = cells.entries.data();
    return spanOf(&cells);
  }

  /// The scan observes the cell of entry x (E or O).
  void forget(NdtEntry* x) {
    if (!NdtCells::live(*x)) return;
    x->m.scale(c_.a);
    if (!NdtCells::live(*x)) {
      cells_->drop(x);  // underflow: nothing is left to keep
    } else if (!(x->m.w >= c_.min_weight)) {
      low_.push_back(static_cast<std::size_t>(x - base_));
    }
  }
  /// Every entry of `sp` (cells of a square classified as `box`) whose cell the scan observes.
  void forgetObserved(const NdtSpan& sp, const SquareInfo& box) {
    sp.forEach([&](NdtEntry* x) {
      if (!NdtCells::live(*x)) return;
      std::uint32_t lx, ly;
      mortonCell(x->code, &lx, &ly);
      const CellClass cls = cls_.classifyCell(ix0_ + lx, iy0_ + ly, box);
      if (cls == CellClass::kEmpty || cls == CellClass::kOccupied) forget(x);
    });
  }

  /// Adds the end-points, caps the weights, drops the Gaussians under the threshold.
  void finish() {
    NdtCells& cells = *cells_;
    NdtEntry* e = nullptr;
    for (const NdtPoint* p = first_; p != last_; ++p) {
      if (p == first_ || p->code != p[-1].code) {
        if (e != nullptr) settle(e);
        e = cells.find(p->code);
        if (!NdtCells::live(*e)) --cells.dead;  // revived below
      }
      e->m.add(c_.g, p->x, p->y);
    }
    if (e != nullptr) settle(e);
    for (std::size_t i : low_) {
      NdtEntry& x = cells.entries[i];
      if (NdtCells::live(x) && !(x.m.w >= c_.min_weight)) cells.drop(&x);
    }
    cells.removeDeadIfMany();
    cells_ = nullptr;
  }

 private:
  // A cell that took end-points: the cap, and the drop test.
  void settle(NdtEntry* x) {
    if (x->m.w > c_.cap) x->m.scale(c_.cap / x->m.w);
    if (!(x->m.w >= c_.min_weight)) low_.push_back(static_cast<std::size_t>(x - base_));
  }

  const ScanClassifier& cls_;
  const NdtConsts c_;
  NdtCells* cells_ = nullptr;       // the block's, from begin() to finish()
  const NdtEntry* base_ = nullptr;  // its entries
  std::int64_t ix0_ = 0, iy0_ = 0;
  const NdtPoint *first_ = nullptr, *last_ = nullptr;
  std::vector<std::size_t> low_;  // entries under the threshold after their forgetting
};

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_PAYLOADS_NDT_UPDATE_H_
