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
  // quadrantBuckets(): per sign pair (a, b) of the sensor-frame offset, D = aX + bY and the
  // numerator as multiples of the map-frame dx and dy.
  const double c = s_.cos_theta, sn = s_.sin_theta, scale = s_.sectors.scale();
  for (std::size_t q = 0; q < 4; ++q) {
    const double a = (q & 1) ? -1.0 : 1.0, b = (q & 2) ? -1.0 : 1.0;
    const double nb = (3.0 + a) * scale, ny = a * scale;  // exact: scale is a power of two
    QuadrantCoeffs& k = quadrant_[q];
    k.dx = a * c - b * sn;
    k.dy = a * sn + b * c;
    k.nx = nb * k.dx - ny * sn;
    k.ny = nb * k.dy + ny * c;
  }
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
    long j = s_.tableSector(dx, dy);  // exact, unless kUnsure
    if (j < 0) j = box.narrow ? sectorIn(dx, dy, box, box.slo) : beamOf(dx, dy);
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

/// The cells holding a hit endpoint of the square's beams in each of kGroups 4 x 4 groups (group
/// keys `keys`, PreparedScan::groupKey): a compare and a mask per beam and group, without a
/// branch (vectorised).
template <std::size_t kGroups>
[[gnu::always_inline]] inline void ScanClassifier::hitMasks(const std::uint32_t* keys,
                                                            const SquareInfo& box,
                                                            std::uint32_t* hit) const {
  const std::uint32_t* group = s_.hit_group.data();
  const std::uint32_t* bit = s_.hit_bit.data();
  for (std::size_t g = 0; g < kGroups; ++g) hit[g] = 0;
  for (int j = box.jlo; j <= box.jhi; ++j) {
    const auto ju = static_cast<std::size_t>(j);
    const std::uint32_t gj = group[ju], bj = bit[ju];
    for (std::size_t g = 0; g < kGroups; ++g) hit[g] |= gj == keys[g] ? bj : 0u;
  }
}

inline CellMasks ScanClassifier::classify4x4(std::int64_t ix0, std::int64_t iy0,
                                             const SquareInfo& box) const {
  CellMasks m;
  classifyGroups<4>(ix0, iy0, box, &m);
  return m;
}

inline TileMasks ScanClassifier::classifyTileCells(int t, std::int64_t ix0, std::int64_t iy0,
                                                   const SquareInfo& box) const {
  TileMasks m;
  if (box.cls == CellClass::kEmpty) {
    m.e = t == 3 ? ~std::uint64_t{0} : 0x0F0F0F0Full;
    return m;
  }
  if (box.cls == CellClass::kUnknown) return m;
  if (t == 3 && fewSectors(box)) {
    if (classifyTile(ix0, iy0, box, &m)) return m;
    std::array<CellMasks, 4> g;  // many boundaries: cell by cell is cheaper
    classifyGroups<8>(ix0, iy0, box, g.data());
    for (unsigned q = 0; q < 4; ++q) placeGroup(g[q], 4 * (q & 1) + 32 * (q >> 1), &m);
    return m;
  }
  if (t == 2) {
    placeGroup(classifyGroup(ix0, iy0, box), 0, &m);
    return m;
  }
  // Many sectors (near the sensor): each 4 x 4 quadrant from its own square class.
  for (unsigned q = 0; q < 4; ++q) {
    const std::int64_t cx = ix0 + ((q & 1) ? 4 : 0), cy = iy0 + ((q & 2) ? 4 : 0);
    const SquareInfo sub = classifySquare(2, cx, cy, box);
    placeGroup(classifyGroup(cx, cy, sub), 4 * (q & 1) + 32 * (q >> 1), &m);
  }
  return m;
}

inline CellMasks ScanClassifier::classifyGroup(std::int64_t ix0, std::int64_t iy0,
                                               const SquareInfo& box) const {
  switch (box.cls) {
    case CellClass::kUnknown:
      return {};
    case CellClass::kEmpty:
      return {0xFFFFu, 0};
    default:
      break;
  }
  if (fewSectors(box)) return classify4x4(ix0, iy0, box);
  CellMasks m;
  for (unsigned i = 0; i < 16; ++i) {
    const CellClass c = classifyCell(ix0 + (i & 3), iy0 + (i >> 2), box);
    m.e |= static_cast<std::uint32_t>(c == CellClass::kEmpty) << i;
    m.o |= static_cast<std::uint32_t>(c == CellClass::kOccupied) << i;
  }
  return m;
}

/// Group masks g (bit x + 4 y) into tile masks (bit x + 8 y) from bit `shift` on.
inline void ScanClassifier::placeGroup(const CellMasks& g, unsigned shift, TileMasks* m) {
  const auto spread = [](std::uint64_t v) {
    return (v & 0xF) | ((v & 0xF0) << 4) | ((v & 0xF00) << 8) | ((v & 0xF000) << 12);
  };
  m->e |= spread(g.e) << shift;
  m->o |= spread(g.o) << shift;
}

/// The 4 x 4 groups of the kSide x kSide square at (ix0, iy0) (a multiple of 4 each), group
/// (gx, gy) at out[gx + gy kSide / 4]. Distances are separable over the square's columns and rows;
/// every cell finds its sector in the pseudo-bearing table (exact, no trigonometry), and only a
/// cell in a bucket near a boundary (about one in 10-20) tests the boundaries (sectorIn). The
/// loops over a group's 16 cells are branch-free; the hits of the square's beams are gathered
/// once, and the columns' and rows' terms are computed once for all groups. Such a square
/// (fewSectors) never holds the sensor, so no cell here has the offset (0, 0) (tableSector).
template <std::size_t kSide>
[[gnu::always_inline]] inline void ScanClassifier::classifyGroups(std::int64_t ix0,
                                                                  std::int64_t iy0,
                                                                  const SquareInfo& box,
                                                                  CellMasks* out) const {
  constexpr std::size_t kPerRow = kSide / 4, kGroups = kPerRow * kPerRow;
  // The reference's arithmetic: dx = (ix + 1/2) res - px, d2 = dx dx + dy dy.
  // (x0 + i) + 1/2 = x0 + (i + 1/2) exactly (cell indices are far below 2^51): one conversion.
  const double x0 = static_cast<double>(ix0), y0 = static_cast<double>(iy0);
  std::array<double, kSide> dx, dy, dx2, dy2;
  for (std::size_t i = 0; i < kSide; ++i) {
    const double half = static_cast<double>(i) + 0.5;
    dx[i] = (x0 + half) * s_.res - s_.px;
    dy[i] = (y0 + half) * s_.res - s_.py;
    dx2[i] = dx[i] * dx[i];
    dy2[i] = dy[i] * dy[i];
  }
  std::array<std::uint32_t, kGroups> keys, hit;
  for (std::size_t g = 0; g < kGroups; ++g) {
    keys[g] = s_.groupKey(ix0 + static_cast<std::int64_t>(4 * (g % kPerRow)),
                          iy0 + static_cast<std::int64_t>(4 * (g / kPerRow)));
  }
  hitMasks<kGroups>(keys.data(), box, hit.data());
  const auto finish = [&](std::size_t g, const double* te, const double* to) {
    const double* gx2 = dx2.data() + 4 * (g % kPerRow);
    const double* gy2 = dy2.data() + 4 * (g / kPerRow);
    std::array<double, 16> d2;
    for (std::size_t i = 0; i < 16; ++i) d2[i] = gx2[i & 3] + gy2[i >> 2];
    const std::uint32_t e = compareMask16<true>(d2.data(), te);
    const std::uint32_t o = compareMask16<false>(d2.data(), to);
    out[g].e = e & ~hit[g];
    out[g].o = (o & ~e) | hit[g];
  };
  if (box.single) {  // one beam: distances alone
    const LeafTest t = s_.leaf[static_cast<std::size_t>(box.jlo)];
    std::array<double, 16> te, to;
    te.fill(t.e);
    to.fill(t.o);
    for (std::size_t g = 0; g < kGroups; ++g) finish(g, te.data(), to.data());
    return;
  }
  // Each cell's sector (n: outside the fan) from its bucket, or kUnsure.
  const SectorTable& table = s_.sectors;
  std::array<double, kSide> dc, dr, nc, nr;  // by the quotient, when the signs allow
  std::array<double, kSide> cx, sx, cy, sy;  // else the sensor-frame offsets, separable too
  const bool quotient = quadrantCoeffs<kSide>(dx, dy, &dc, &dr, &nc, &nr);
  if (!quotient) {
    for (std::size_t i = 0; i < kSide; ++i) {
      cx[i] = s_.cos_theta * dx[i];
      sx[i] = s_.sin_theta * dx[i];
      cy[i] = s_.cos_theta * dy[i];
      sy[i] = s_.sin_theta * dy[i];
    }
  }
  const std::int32_t* sectors = table.data();
  const LeafTest* leaf = s_.leaf.data();
  const std::uint32_t mask = table.mask();
  for (std::size_t g = 0; g < kGroups; ++g) {
    const std::size_t ox = 4 * (g % kPerRow), oy = 4 * (g / kPerRow);
    std::array<std::uint32_t, 16> bucket;
    if (quotient) {
      std::array<double, 4> gdc, gdr, gnc, gnr;  // the group's columns and rows
      for (std::size_t i = 0; i < 4; ++i) {
        gdc[i] = dc[ox + i];
        gdr[i] = dr[oy + i];
        gnc[i] = nc[ox + i];
        gnr[i] = nr[oy + i];
      }
      quotientBuckets16(gnc.data(), gnr.data(), gdc.data(), gdr.data(), mask, bucket.data());
    } else {
      const double *gcx = cx.data() + ox, *gsx = sx.data() + ox;
      const double *gcy = cy.data() + oy, *gsy = sy.data() + oy;
      for (std::size_t i = 0; i < 16; ++i) {
        bucket[i] = table.bucket(gcx[i & 3] + gsy[i >> 2], gcy[i >> 2] - gsx[i & 3]);
      }
    }
    std::array<std::int32_t, 16> sector;
    for (std::size_t i = 0; i < 16; ++i) sector[i] = sectors[bucket[i]];
    for (std::uint32_t unsure = negativeMask16(sector.data()) & ~hit[g]; unsure != 0;
         unsure &= unsure - 1) {
      const auto i = static_cast<unsigned>(__builtin_ctz(unsure));
      // Start from the sector of the bucket before (this one is near a boundary).
      const long j = sectorIn(dx[ox + (i & 3)], dy[oy + (i >> 2)], box,
                              sectors[(bucket[i] - 1u) & table.mask()]);
      sector[i] = j < 0 || j >= s_.n ? s_.n : static_cast<std::int32_t>(j);
    }
    // The leaf tests of each cell's beam (leaf[n]: never E, never O; a hit cell's is not used).
    std::array<double, 16> te, to;
    for (std::size_t i = 0; i < 16; ++i) {
      const LeafTest& t = leaf[static_cast<std::size_t>(std::max(sector[i], 0))];
      te[i] = t.e;
      to[i] = t.o;
    }
    finish(g, te.data(), to.data());
  }
}

/// The quotient's coefficient terms of the columns (dc, nc) and rows (dr, nr) of a square of
/// cells whose sensor-frame offsets (X, Y) = (c dx + s dy, c dy - s dx) keep their signs a, b
/// over the square, if they do (else false). There the pseudo-bearing times the table's scale is
/// ((3 + a) scale D + a scale Y) / D with D = |X| + |Y| = aX + bY: numerator and denominator are
/// a multiple of dx plus a multiple of dy (coefficients per scan and sign pair), so a cell costs
/// two additions, a division and a conversion, without selects (vectorised). X and Y are linear
/// over the square, so their extremes over it are sums of the extremes of their dx and dy terms;
/// a square within 1e-12 (|dx| + |dy|) of an axis (far above the rounding of X and Y) is left to
/// SectorTable::bucket. The quotient differs from pseudoBearing() scale by under 1e-13 scale (a
/// few ulps on terms of at most 7 scale |d|, over D >= |d|), far inside the table's margin, which
/// its sure buckets allow for.
template <std::size_t kSide>
inline bool ScanClassifier::quadrantCoeffs(const std::array<double, kSide>& dx,
                                           const std::array<double, kSide>& dy,
                                           std::array<double, kSide>* dc,
                                           std::array<double, kSide>* dr,
                                           std::array<double, kSide>* nc,
                                           std::array<double, kSide>* nr) const {
  constexpr std::size_t kLast = kSide - 1;
  const double c = s_.cos_theta, sn = s_.sin_theta;
  const double cx0 = c * dx[0], cx3 = c * dx[kLast], sx0 = sn * dx[0], sx3 = sn * dx[kLast];
  const double cy0 = c * dy[0], cy3 = c * dy[kLast], sy0 = sn * dy[0], sy3 = sn * dy[kLast];
  const double x_lo = std::min(cx0, cx3) + std::min(sy0, sy3);
  const double x_hi = std::max(cx0, cx3) + std::max(sy0, sy3);
  const double y_lo = std::min(cy0, cy3) - std::max(sx0, sx3);
  const double y_hi = std::max(cy0, cy3) - std::min(sx0, sx3);
  const double tiny = 1e-12 * (std::max(std::fabs(dx[0]), std::fabs(dx[kLast])) +
                               std::max(std::fabs(dy[0]), std::fabs(dy[kLast])));
  if (!(x_lo > tiny || x_hi < -tiny) || !(y_lo > tiny || y_hi < -tiny)) return false;
  const QuadrantCoeffs& k = quadrant_[(x_lo > 0.0 ? 0u : 1u) | (y_lo > 0.0 ? 0u : 2u)];
  for (std::size_t i = 0; i < kSide; ++i) {
    (*dc)[i] = k.dx * dx[i];
    (*dr)[i] = k.dy * dy[i];
    (*nc)[i] = k.nx * dx[i];
    (*nr)[i] = k.ny * dy[i];
  }
  return true;
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

/// beamOf() for a cell of a narrow square, without a bearing: sector `start` (clamped to the
/// square's sectors slo..shi), moved to the neighbour while
/// the cell is surely past the next boundary or surely before its own, and taken once it is
/// surely past its own (or it is slo) and surely before the next (or it is shi). Within a narrow
/// square the sides are monotone in the boundary, so this is the sector that testing every
/// boundary would give; a cell too close to a boundary to tell gets the reference's rounding,
/// via beamOf. Two cross products when the candidate is right.
inline long ScanClassifier::sectorIn(double dx, double dy, const SquareInfo& box, int start) const {
  const double tol = kRayMargin * (std::fabs(dx) + std::fabs(dy));
  const double* bx = s_.bnd_x.data();
  const double* by = s_.bnd_y.data();
  const auto cross = [&](int k) {
    const auto ku = static_cast<std::size_t>(k);
    return bx[ku] * dy - by[ku] * dx;
  };
  int j = std::min(std::max(start, box.slo), box.shi);
  for (;;) {
    if (j < box.shi) {
      const double next = cross(j + 1);
      if (next > tol) {
        ++j;
        continue;
      }
      if (!(next < -tol)) return beamOf(dx, dy);
    }
    if (j > box.slo) {
      const double own = cross(j);
      if (own < -tol) {
        --j;
        continue;
      }
      if (!(own > tol)) return beamOf(dx, dy);
    }
    return j;
  }
}

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_CLASSIFY_SCAN_CLASSIFIER_CELLS_INL_H_
