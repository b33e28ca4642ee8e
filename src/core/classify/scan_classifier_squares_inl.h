// Inline definitions of the ScanClassifier (scan_classifier.h), part 2: squares of cells, from
// their distance range and bearing interval against the prepared scan's min / max table.
#ifndef WAVOG_MAPPING_SRC_CORE_CLASSIFY_SCAN_CLASSIFIER_SQUARES_INL_H_
#define WAVOG_MAPPING_SRC_CORE_CLASSIFY_SCAN_CLASSIFIER_SQUARES_INL_H_

#include "classify/scan_classifier.h"

namespace wavog {
namespace detail {

/// Squared distance from the sensor to the nearest point of `sq` (0 when it holds the sensor).
inline double ScanClassifier::nearest2(const Square& sq) const {
  const double nx = std::max(std::max(sq.x0 - s_.px, 0.0), s_.px - sq.x1);
  const double ny = std::max(std::max(sq.y0 - s_.py, 0.0), s_.py - sq.y1);
  return nx * nx + ny * ny;
}

/// Squared distance from the sensor to the farthest corner of `sq`.
inline double ScanClassifier::farthest2(const Square& sq) const {
  const double fx = std::max(std::fabs(sq.x0 - s_.px), std::fabs(sq.x1 - s_.px));
  const double fy = std::max(std::fabs(sq.y0 - s_.py), std::fabs(sq.y1 - s_.py));
  return fx * fx + fy * fy;
}

/// The square of side 2^l cells at cell (ix0, iy0), in metres.
inline ScanClassifier::Square ScanClassifier::square(int l, std::int64_t ix0,
                                                     std::int64_t iy0) const {
  const double size = static_cast<double>(std::int64_t{1} << l) * s_.res;
  const double x0 = static_cast<double>(ix0) * s_.res, y0 = static_cast<double>(iy0) * s_.res;
  return {x0, y0, x0 + size, y0 + size};
}

/// A sub-square of a single-beam square needs ranges only; of a narrow one, boundary tests.
inline SquareInfo ScanClassifier::classifySquare(int l, std::int64_t ix0, std::int64_t iy0,
                                                 const SquareInfo& parent) const {
  if (parent.single) {
    SquareInfo info = parent;
    info.cls = classifyInBeam(l, ix0, iy0, parent.jlo);
    return info;
  }
  if (parent.narrow) return classifyInRange(l, ix0, iy0, parent);
  return classifySquare(l, ix0, iy0);
}

/// Corners of square `sq` (not holding the sensor) that bound its bearing interval, counter-
/// clockwise first (a) and last (b), as offsets from the sensor. Which corners they are follows
/// from where the sensor lies: left / right / within in x, below / above / within in y.
inline void ScanClassifier::extremeCorners(const Square& sq, double* ax, double* ay, double* bx,
                                           double* by) const {
  const double x0 = sq.x0, y0 = sq.y0, x1 = sq.x1, y1 = sq.y1, px = s_.px, py = s_.py;
  if (px < x0) {
    if (py < y0) {
      *ax = x1, *ay = y0, *bx = x0, *by = y1;
    } else if (py > y1) {
      *ax = x0, *ay = y0, *bx = x1, *by = y1;
    } else {
      *ax = x0, *ay = y0, *bx = x0, *by = y1;
    }
  } else if (px > x1) {
    if (py < y0) {
      *ax = x1, *ay = y1, *bx = x0, *by = y0;
    } else if (py > y1) {
      *ax = x0, *ay = y1, *bx = x1, *by = y0;
    } else {
      *ax = x1, *ay = y1, *bx = x1, *by = y0;
    }
  } else if (py < y0) {
    *ax = x1, *ay = y0, *bx = x0, *by = y0;
  } else {
    *ax = x0, *ay = y1, *bx = x1, *by = y1;
  }
  *ax -= px, *ay -= py, *bx -= px, *by -= py;
}

/// classifySquare() for a sub-square of a narrow square: its beams are those of the parent from
/// the last boundary its first corner is surely past to the last one its last corner may be
/// past (conservative both ways).
inline SquareInfo ScanClassifier::classifyInRange(int l, std::int64_t ix0, std::int64_t iy0,
                                                  const SquareInfo& parent) const {
  const Square sq = square(l, ix0, iy0);
  SquareInfo info = parent;
  double ax, ay, bx, by;
  extremeCorners(sq, &ax, &ay, &bx, &by);
  // A corner in a sure bucket of the table is surely past every boundary of its sector and
  // before, surely before every later one: both bisections would return its sector, clamped.
  const std::int32_t sa = s_.tableSector(ax, ay), sb = s_.tableSector(bx, by);
  info.slo = sa >= 0 && sa < s_.n
                 ? std::min(std::max(static_cast<int>(sa), parent.slo), parent.shi)
                 : lastSurelyPast(ax, ay, kRayMargin * (std::fabs(ax) + std::fabs(ay)), parent.slo,
                                  parent.shi);
  info.shi = sb >= 0 && sb < s_.n
                 ? std::min(std::max(static_cast<int>(sb), info.slo), parent.shi)
                 : lastNotSurelyBefore(bx, by, kRayMargin * (std::fabs(bx) + std::fabs(by)),
                                       info.slo, parent.shi);
  info.jlo = std::max(info.slo, 0);
  info.jhi = std::min(info.shi, s_.n - 1);
  const bool partial = info.slo < 0 || info.shi > s_.n - 1;
  info.single = !partial && info.jlo == info.jhi;
  info.cls =
      info.jlo > info.jhi ? CellClass::kUnknown : rangeClass(sq, info.jlo, info.jhi, partial);
  return info;
}

/// Class of square `sq` whose cells lie in sectors jlo..jhi (`partial`: or outside the fan),
/// from its distance range against the beams' limits.
inline CellClass ScanClassifier::rangeClass(const Square& sq, int jlo, int jhi,
                                            bool partial) const {
  if (nearest2(sq) > s_.maxU2(jlo, jhi)) return CellClass::kUnknown;
  if (farthest2(sq) < s_.minE2(jlo, jhi)) {
    return (partial || s_.anyInvalid(jlo, jhi)) ? CellClass::kFreeOrUnknown : CellClass::kEmpty;
  }
  return CellClass::kMixed;
}

/// Class of a square that lies in sector j (not holding the sensor). Only beam j can put a hit
/// in it, so the class follows from its distance range against beam j's limits.
inline CellClass ScanClassifier::classifyInBeam(int l, std::int64_t ix0, std::int64_t iy0,
                                                int j) const {
  const Square sq = square(l, ix0, iy0);
  const auto ju = static_cast<std::size_t>(j);
  if (nearest2(sq) > s_.u2(ju)) return CellClass::kUnknown;  // also invalid beams (u2 = -1)
  if (farthest2(sq) < s_.e2(ju)) return CellClass::kEmpty;
  return s_.kind[ju] == BeamKind::kClear ? CellClass::kFreeOrUnknown : CellClass::kMixed;
}

/// Beams j whose sector may hold a direction of offsets [a_lo, a_hi] past the seam: the cells'
/// lround() lands in [jlo, jhi], clamped to [-1, n] (-1 and n: outside the fan).
inline void ScanClassifier::beamRange(double a_lo, double a_hi, long* jlo, long* jhi) const {
  const double t_lo = (a_lo - kFastAtanError) * s_.inv_inc + s_.t_seam - 0.5 - kIndexSlack;
  const double t_hi = (a_hi + kFastAtanError) * s_.inv_inc + s_.t_seam + 0.5 + kIndexSlack;
  // Clamped both ways: with a tiny beam step t can exceed any integer type.
  const double top = static_cast<double>(s_.n);
  *jlo = static_cast<long>(fastCeil(std::min(std::max(t_lo, -1.0), top)));
  *jhi = static_cast<long>(fastFloor(std::max(std::min(t_hi, top), -1.0)));
}

/// Conservative: kEmpty only if every cell in it is E, kUnknown only if every cell is U,
/// kFreeOrUnknown only if no cell is O.
inline SquareInfo ScanClassifier::classifySquare(int l, std::int64_t ix0, std::int64_t iy0) const {
  SquareInfo info;
  info.jlo = 0;
  info.jhi = s_.n - 1;
  const Square sq = square(l, ix0, iy0);
  if (s_.px >= sq.x0 && s_.px <= sq.x1 && s_.py >= sq.y0 && s_.py <= sq.y1) return info;
  info.cls = CellClass::kUnknown;
  if (nearest2(sq) > reach2_) return info;

  // Bearing interval of the square (convex, not holding the sensor: span < pi).
  double ax, ay, bx, by;
  extremeCorners(sq, &ax, &ay, &bx, &by);
  // Offsets past the seam, in [0, 2 pi); the square wraps the seam when the last is below the
  // first, and is then unwrapped.
  const double lo = s_.offSeam(fastAtan2(ay, ax));
  double hi = s_.offSeam(fastAtan2(by, bx));
  const bool straddles = hi < lo;
  if (straddles) hi += kTwoPi;
  long jlo, jhi;
  beamRange(lo, hi, &jlo, &jhi);
  const long slo = jlo, shi = jhi;  // in [-1, n]: -1 and n are the outside of the fan
  const long last = static_cast<long>(s_.n - 1);
  const bool partial = straddles || jlo < 0 || jhi > last;
  jlo = std::max(jlo, 0L);
  jhi = std::min(jhi, last);
  if (straddles) {
    long klo, khi;
    beamRange(lo - kTwoPi, hi - kTwoPi, &klo, &khi);
    klo = std::max(klo, 0L);
    khi = std::min(khi, last);
    if (klo <= khi) {
      const bool both = jlo <= jhi;  // union covered by its hull: conservative
      jlo = both ? std::min(jlo, klo) : klo;
      jhi = both ? std::max(jhi, khi) : khi;
    }
  }
  if (jlo > jhi) return info;
  info.jlo = static_cast<int>(jlo);
  info.jhi = static_cast<int>(jhi);
  info.single = !partial && jlo == jhi;
  // Narrow, also across an edge of the fan (not the seam): every point and every boundary
  // between its sectors within pi / 2 of each other, so boundary side tests are monotone.
  info.narrow = !straddles && static_cast<double>(shi - slo + 1) * s_.inc < 0.5 * kPi &&
                (hi - lo) + s_.inc < 0.5 * kPi;
  info.slo = static_cast<int>(slo);
  info.shi = static_cast<int>(shi);
  info.cls = rangeClass(sq, info.jlo, info.jhi, partial);
  return info;
}

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_CLASSIFY_SCAN_CLASSIFIER_SQUARES_INL_H_
