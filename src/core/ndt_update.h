// The update of normal-distribution cells by one scan (MapParams::ndt): the scan's end-points
// grouped by block (NdtScanPoints), and per block (updateNdtBlock) the policy on the Gaussians of
// the cells the scan observes, found by a walk over the block's Morton-sorted cells against the
// ScanClassifier (U squares skipped whole, E squares scaled whole, the rest cell by cell), then
// the new end-points. It runs beside the quadtree update of the same block, on the same thread.
// Not installed; included only by src/core/integrate.cpp.
#ifndef WAVOG_MAPPING_SRC_CORE_NDT_UPDATE_H_
#define WAVOG_MAPPING_SRC_CORE_NDT_UPDATE_H_

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "block_hash.h"
#include "ndt_store.h"
#include "scan_classifier.h"

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
      double ex, ey;
      ps.endpoint(j, &ex, &ey);
      const std::int64_t ix = ps.hit_x[j], iy = ps.hit_y[j];
      NdtPoint p;
      p.block = blockKey(floorShift(ix, levels), floorShift(iy, levels));
      p.code = mortonCode(static_cast<std::uint32_t>(ix & mask), static_cast<std::uint32_t>(iy & mask));
      p.beam = static_cast<std::uint32_t>(j);
      p.x = ex - (static_cast<double>(ix) + 0.5) * ps.res;
      p.y = ey - (static_cast<double>(iy) + 0.5) * ps.res;
      points_.push_back(p);
    }
    std::sort(points_.begin(), points_.end(), [](const NdtPoint& a, const NdtPoint& b) {
      if (a.block != b.block) return a.block < b.block;
      if (a.code != b.code) return a.code < b.code;
      return a.beam < b.beam;
    });
  }
  bool empty() const { return points_.empty(); }
  /// The points of block `key`: [*first, *last).
  void inBlock(std::uint64_t key, const NdtPoint** first, const NdtPoint** last) const {
    const auto lo = std::lower_bound(points_.begin(), points_.end(), key,
                                     [](const NdtPoint& p, std::uint64_t k) { return p.block < k; });
    auto hi = lo;
    while (hi != points_.end() && hi->block == key) ++hi;
    *first = points_.data() + (lo - points_.begin());
    *last = points_.data() + (hi - points_.begin());
  }

 private:
  std::vector<NdtPoint> points_;
};

/// The policy on the Gaussians for one scan: an observed cell's moments times `a`, each new
/// end-point weighing `g`, weights capped at `cap`, cells under `min_weight` dropped.
struct NdtConsts {
  double a = 1.0;
  double g = 1.0;
  double cap = std::numeric_limits<double>::infinity();
  double min_weight = 0.0;
};

class NdtBlockUpdate {
 public:
  NdtBlockUpdate(const ScanClassifier& cls, const NdtConsts& c, int levels)
      : cls_(cls), c_(c), levels_(levels) {}

  /// Updates the Gaussians of the block at cell (ix0, iy0), classified as `box`, with the scan's
  /// end-points [first, last) in it. Returns the cells visited.
  std::uint64_t update(NdtCells& cells, std::int64_t ix0, std::int64_t iy0, const SquareInfo& box,
                       const NdtPoint* first, const NdtPoint* last) {
    ix0_ = ix0;
    iy0_ = iy0;
    visited_ = 0;
    low_ = false;
    // New cells first, empty: the observation below leaves them empty.
    for (const NdtPoint* p = first; p != last; ++p) {
      if (p != first && p->code == p[-1].code) continue;
      if (cells.find(p->code) == nullptr) cells.entries.push_back({p->code, {}});
    }
    cells.mergeTailIfLong();
    if (c_.a != 1.0) {
      NdtEntry* base = cells.entries.data();
      observe(base, base + cells.sorted, levels_, ix0, iy0, box);
      for (NdtEntry* e = base + cells.sorted; e != base + cells.entries.size(); ++e) {
        observeCell(e, box);
      }
    }
    NdtEntry* e = nullptr;
    for (const NdtPoint* p = first; p != last; ++p) {
      const bool same = p != first && p->code == p[-1].code;
      if (!same) {
        if (e != nullptr) settle(e);
        e = cells.find(p->code);
      }
      e->m.add(c_.g, p->x, p->y);
    }
    if (e != nullptr) settle(e);
    if (low_) {
      const double min_weight = c_.min_weight;
      cells.removeIf([min_weight](const NdtEntry& x) { return !(x.m.w >= min_weight && x.m.w > 0.0); });
    }
    return visited_;
  }

 private:
  // Sorted entries [b, e) under the square of level l at (ix0, iy0) classified as `box`.
  void observe(NdtEntry* b, NdtEntry* e, int l, std::int64_t ix0, std::int64_t iy0,
               const SquareInfo& box) {
    if (b == e || box.cls == CellClass::kUnknown) return;
    ++visited_;
    if (box.cls == CellClass::kEmpty) {
      for (NdtEntry* x = b; x != e; ++x) forget(x);
      return;
    }
    if (l <= 1 || e - b <= 2) {
      for (NdtEntry* x = b; x != e; ++x) observeCell(x, box);
      return;
    }
    const int shift = 2 * (l - 1);
    const std::int64_t half = std::int64_t{1} << (l - 1);
    NdtEntry* lo = b;
    for (unsigned q = 0; q < 4; ++q) {
      NdtEntry* hi = q == 3 ? e : std::partition_point(lo, e, [shift, q](const NdtEntry& x) {
        return ((x.code >> shift) & 3u) <= q;
      });
      if (lo != hi) {
        const std::int64_t cx = ix0 + ((q & 1u) ? half : 0), cy = iy0 + ((q & 2u) ? half : 0);
        observe(lo, hi, l - 1, cx, cy, cls_.classifySquare(l - 1, cx, cy, box));
      }
      lo = hi;
    }
  }

  // One entry of a square classified as `box`: forgotten when the scan observes its cell.
  void observeCell(NdtEntry* x, const SquareInfo& box) {
    ++visited_;
    std::uint32_t lx, ly;
    mortonCell(x->code, &lx, &ly);
    const CellClass cls = cls_.classifyCell(ix0_ + lx, iy0_ + ly, box);
    if (cls == CellClass::kEmpty || cls == CellClass::kOccupied) forget(x);
  }

  void forget(NdtEntry* x) {
    x->m.scale(c_.a);
    if (!(x->m.w >= c_.min_weight && x->m.w > 0.0)) low_ = true;
  }

  // A cell that took end-points: the cap, and the drop test.
  void settle(NdtEntry* x) {
    if (x->m.w > c_.cap) x->m.scale(c_.cap / x->m.w);
    if (!(x->m.w >= c_.min_weight && x->m.w > 0.0)) low_ = true;
  }

  const ScanClassifier& cls_;
  const NdtConsts c_;
  const int levels_;
  std::int64_t ix0_ = 0, iy0_ = 0;
  std::uint64_t visited_ = 0;
  bool low_ = false;
};

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_NDT_UPDATE_H_
