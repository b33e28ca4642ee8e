// Inline definitions of the ScanClassifier (scan_classifier.h), part 1: finest cells and 4 x 4
// groups of cells, and the beam lookup they share (polynomial bearing, or sector boundaries).
#ifndef WAVOG_MAPPING_SRC_CORE_CLASSIFY_SCAN_CLASSIFIER_CELLS_INL_H_
#define WAVOG_MAPPING_SRC_CORE_CLASSIFY_SCAN_CLASSIFIER_CELLS_INL_H_

#include <array>

#include "classify/scan_classifier.h"

namespace wavog {
namespace detail {

inline ScanStatus ScanClassifier::prepare(const MapParams& params, const Pose2& pose,
                                          const ScanView& scan, IntegrateStats* st) {
  const ScanStatus status = s_.prepare(params, pose, scan, st);
  reach2_ = squaredLimit(s_.reach);
  return status;
}

/// O if a hit falls in the cell (O wins), else sampled at the cell centre with the sector model.
/// The dense reference in test/core repeats this rule with std::atan2 cell by cell; this gives
/// the same class faster: only beams of `box` can have their endpoint in the cell, and in a
/// single-beam square the sector is known without any bearing.
inline CellClass ScanClassifier::classifyCell(std::int64_t ix, std::int64_t iy,
                                              const SquareInfo& box) const {
  const double dx = (static_cast<double>(ix) + 0.5) * s_.res - s_.px;
  const double dy = (static_cast<double>(iy) + 0.5) * s_.res - s_.py;
  std::size_t ju;
  if (box.single) {
    ju = static_cast<std::size_t>(box.jlo);
    if (s_.hitsCell(ju, ix, iy)) return CellClass::kOccupied;
  } else {
    if (isHitCell(ix, iy, box)) return CellClass::kOccupied;
    const long j = box.narrow ? beamIn(dx, dy, box) : beamOf(dx, dy);
    if (j < 0 || j >= s_.n) return CellClass::kUnknown;
    ju = static_cast<std::size_t>(j);
  }
  return cellAt(ju, dx * dx + dy * dy);
}

/// The sector model's class of a cell (not holding a hit) in sector j whose centre lies at
/// squared distance d2: the reference's sqrt(d2) < ze (E), else hit and sqrt(d2) <= zu (O).
inline CellClass ScanClassifier::cellAt(std::size_t j, double d2) const {
  const LeafTest& t = s_.leaf[j];
  return d2 < t.e ? CellClass::kEmpty : d2 <= t.o ? CellClass::kOccupied : CellClass::kUnknown;
}

/// True if a hit endpoint lies in cell (ix, iy) of square `box` (only its beams can).
inline bool ScanClassifier::isHitCell(std::int64_t ix, std::int64_t iy,
                                      const SquareInfo& box) const {
  constexpr int kScanLimit = 8;
  if (box.jhi - box.jlo >= kScanLimit) {
    return std::binary_search(s_.hits.begin(), s_.hits.end(), PreparedScan::cellKey(ix, iy));
  }
  for (int j = box.jlo; j <= box.jhi; ++j) {
    if (s_.hitsCell(static_cast<std::size_t>(j), ix, iy)) return true;
  }
  return false;
}

/// The cells of the 4 x 4 square at (ix0, iy0) holding a hit endpoint of the square's beams.
[[gnu::always_inline]] inline std::uint32_t ScanClassifier::hitMask4x4(
    std::int64_t ix0, std::int64_t iy0, const SquareInfo& box) const {
  std::uint32_t hit = 0;
  for (int j = box.jlo; j <= box.jhi; ++j) {
    const auto ju = static_cast<std::size_t>(j);
    if (s_.kind[ju] != BeamKind::kHit) continue;
    const std::int64_t hx = s_.hit_x[ju] - ix0, hy = s_.hit_y[ju] - iy0;
    if (hx >= 0 && hx < 4 && hy >= 0 && hy < 4) hit |= 1u << (hx + 4 * hy);
  }
  return hit;
}

/// Distances and cross products are separable over the grid's 4 columns and 4 rows, and the
/// hits of the square's beams are gathered once.
inline CellMasks ScanClassifier::classify4x4(std::int64_t ix0, std::int64_t iy0,
                                             const SquareInfo& box) const {
  // The reference's arithmetic: dx = (ix + 1/2) res - px, d2 = dx dx + dy dy.
  std::array<double, 4> dx, dy, dx2, dy2;
  for (std::size_t i = 0; i < 4; ++i) {
    dx[i] = (static_cast<double>(ix0 + static_cast<std::int64_t>(i)) + 0.5) * s_.res - s_.px;
    dy[i] = (static_cast<double>(iy0 + static_cast<std::int64_t>(i)) + 0.5) * s_.res - s_.py;
    dx2[i] = dx[i] * dx[i];
    dy2[i] = dy[i] * dy[i];
  }
  const std::uint32_t hit = hitMask4x4(ix0, iy0, box);
  if (box.single) {  // one beam: distances alone
    const LeafTest t = s_.leaf[static_cast<std::size_t>(box.jlo)];
    std::uint32_t e = 0, o = 0;
    for (unsigned i = 0; i < 16; ++i) {
      const double d2 = dx2[i & 3] + dy2[i >> 2];
      e |= static_cast<std::uint32_t>(d2 < t.e) << i;
      o |= static_cast<std::uint32_t>(d2 <= t.o) << i;
    }
    CellMasks m;
    m.e = e & ~hit;
    m.o = (o & ~e) | hit;
    return m;
  }
  // A few sectors. Where the distance alone decides (E in every sector of the square, or U in
  // every one: outside sectors and invalid beams count as U), no sector is needed.
  double te_min =
      box.slo < 0 || box.shi > s_.n - 1 ? -1.0 : std::numeric_limits<double>::infinity();
  double te_max = -1.0, tu_max = -1.0;
  for (int j = box.jlo; j <= box.jhi; ++j) {
    const LeafTest& t = s_.leaf[static_cast<std::size_t>(j)];
    te_min = std::min(te_min, t.e);
    te_max = std::max(te_max, t.e);
    tu_max = std::max(tu_max, t.o);
  }
  CellMasks m;
  m.o = hit;
  // Up to kLinearSectors boundaries, their cross products' two terms are separable too: the
  // same products beamIn() forms, computed once per row and column.
  const int nb = box.shi - box.slo;
  std::array<std::array<double, 4>, kLinearSectors> bxdy, bydx;
  if (nb <= kLinearSectors) {
    for (int b = 0; b < nb; ++b) {
      const auto ku = static_cast<std::size_t>(box.slo + 1 + b), bu = static_cast<std::size_t>(b);
      for (std::size_t t = 0; t < 4; ++t) {
        bxdy[bu][t] = s_.bnd_x[ku] * dy[t];
        bydx[bu][t] = s_.bnd_y[ku] * dx[t];
      }
    }
  }
  for (unsigned i = 0; i < 16; ++i) {
    if ((hit >> i) & 1u) continue;
    const unsigned c = i & 3, r = i >> 2;
    const double d2 = dx2[c] + dy2[r];
    if (d2 < te_min) {
      m.e |= 1u << i;
      continue;
    }
    if (d2 >= te_max && d2 > tu_max) continue;  // U
    long j;
    if (nb <= kLinearSectors) {  // beamIn()'s linear test, on the stored products
      j = linearSector(box.slo, nb, kRayMargin * (std::fabs(dx[c]) + std::fabs(dy[r])),
                       [&](std::size_t b) { return bxdy[b][r] - bydx[b][c]; });
      if (j == kUnsure) j = beamOf(dx[c], dy[r]);
    } else {
      j = beamIn(dx[c], dy[r], box);
    }
    if (j < 0 || j >= s_.n) continue;  // outside the fan: U
    const CellClass cls = cellAt(static_cast<std::size_t>(j), d2);
    m.e |= static_cast<std::uint32_t>(cls == CellClass::kEmpty) << i;
    m.o |= static_cast<std::uint32_t>(cls == CellClass::kOccupied) << i;
  }
  return m;
}

/// lround((normalise(atan2(dy, dx) - theta) - amin) / inc), as the reference computes it: the
/// polynomial atan2 decides unless its error could move the result across a rounding boundary
/// or the seam, then std::atan2 does.
inline long ScanClassifier::beamOf(double dx, double dy) const {
  const double off = s_.offSeam(fastAtan2(dy, dx));
  const double u = off * s_.inv_inc + s_.t_seam + 0.5;  // lround(t) = floor(t + 1/2) off the halves
  const double f = fastFloor(u);
  if (u - f > s_.fast_guard && u - f < 1.0 - s_.fast_guard && off > kFastAtanError &&
      off < kTwoPi - kFastAtanError) {
    return static_cast<long>(f);
  }
  return std::lround((s_.normalise(std::atan2(dy, dx) - s_.theta) - s_.amin) / s_.inc);
}

// Sector boundaries by cross products. Within a narrow square's sectors (under pi / 2) the
// side of a direction against boundary k is monotone in k, so the tests bisect. "Surely" means
// by more than kRayMargin radians (tol = kRayMargin * (|dx| + |dy|) bounds that from above).

/// Largest k in [lo, hi] such that (dx, dy) is surely past boundary k (lo when none is tested).
inline int ScanClassifier::lastSurelyPast(double dx, double dy, double tol, int lo, int hi) const {
  while (lo < hi) {
    const int mid = lo + (hi - lo + 1) / 2;
    const auto m = static_cast<std::size_t>(mid);
    const bool past = s_.bnd_x[m] * dy - s_.bnd_y[m] * dx > tol;  // branch-free: a coin toss
    lo = past ? mid : lo;
    hi = past ? hi : mid - 1;
  }
  return lo;
}

/// Largest k in [lo, hi] such that (dx, dy) is not surely before boundary k (lo when none).
inline int ScanClassifier::lastNotSurelyBefore(double dx, double dy, double tol, int lo,
                                               int hi) const {
  while (lo < hi) {
    const int mid = lo + (hi - lo + 1) / 2;
    const auto m = static_cast<std::size_t>(mid);
    const bool before = s_.bnd_x[m] * dy - s_.bnd_y[m] * dx < -tol;
    hi = before ? mid - 1 : hi;
    lo = before ? lo : mid;
  }
  return lo;
}

/// The sector, among slo..slo + nb, of a direction whose cross product with boundary
/// slo + 1 + b is cross(b): slo plus the boundaries it is surely past (by more than tol), if it
/// is surely on one side of each and past none after one it is before; else kUnsure.
template <typename Cross>
inline long ScanClassifier::linearSector(int slo, int nb, double tol, Cross cross) {
  long j = slo;
  bool ok = true, before = false;
  for (int b = 0; b < nb; ++b) {
    const double x = cross(static_cast<std::size_t>(b));
    if (x > tol) {
      ok = ok && !before;
      ++j;
    } else if (x < -tol) {
      before = true;
    } else {
      ok = false;
    }
  }
  return ok ? j : kUnsure;
}

/// beamOf() for a cell of a narrow square: the last boundary it is surely past, unless it is
/// too close to the next one to tell (then the reference's rounding decides, via beamOf). Up to
/// kLinearSectors boundaries each one is tested (past the first j - slo of them, before the
/// rest); beyond, they are bisected.
inline long ScanClassifier::beamIn(double dx, double dy, const SquareInfo& box) const {
  const double tol = kRayMargin * (std::fabs(dx) + std::fabs(dy));
  if (box.shi - box.slo <= kLinearSectors) {
    const long j = linearSector(box.slo, box.shi - box.slo, tol, [&](std::size_t b) {
      const std::size_t ku = static_cast<std::size_t>(box.slo) + 1 + b;
      return s_.bnd_x[ku] * dy - s_.bnd_y[ku] * dx;
    });
    return j != kUnsure ? j : beamOf(dx, dy);
  }
  const int j = lastSurelyPast(dx, dy, tol, box.slo, box.shi);
  if (j < box.shi) {
    const auto m = static_cast<std::size_t>(j + 1);
    if (!(s_.bnd_x[m] * dy - s_.bnd_y[m] * dx < -tol)) return beamOf(dx, dy);
  }
  return j;
}

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_CLASSIFY_SCAN_CLASSIFIER_CELLS_INL_H_
