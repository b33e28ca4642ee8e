// Coarse-to-fine integration of one scan (ALGORITHM.md sections 3 and 6).
//
// Per scan: beams are classified per REP 117 into hit / clearing / invalid, with their E and U
// limits zE, zU; sparse tables give min zE and max zU over any beam interval in O(1); hit cells
// are binned. Per node: the node's range and bearing interval against those tables give U, E,
// FREE_OR_UNKNOWN or MIXED without looping over beams (conservative: never E or U wrongly), and
// the beams that may meet it, which its sub-squares and cells inherit (inside one sector: ranges
// only; within under 90 deg of sectors: boundary rays by cross products, no bearings).
// U is skipped, E is applied at the node's own scale (a lazy tag with forgetting), the rest
// descends; finest cells get exactly the class the dense reference gives them, cell by cell.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "map_impl.h"
#include "wavog_mapping/core/haar.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog {
namespace {

using detail::Block;
using detail::Node;

constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;
// Slack on beam-index bounds (in beams) so rounding in atan2 never misses a beam.
constexpr double kIndexSlack = 1e-6;
// Numerical floor of the "E update changes nothing" test (log-odds).
constexpr double kUnchangedFloor = 1e-9;

// floor / ceil without a libm call (x86-64's baseline has no rounding instruction). Magnitudes
// of 2^52 and more are integers already; NaN goes to std::floor / std::ceil.
inline double fastFloor(double v) {
  if (!(std::fabs(v) < 4503599627370496.0)) return std::floor(v);
  const auto t = static_cast<double>(static_cast<std::int64_t>(v));
  return t > v ? t - 1.0 : t;
}
inline double fastCeil(double v) {
  if (!(std::fabs(v) < 4503599627370496.0)) return std::ceil(v);
  const auto t = static_cast<double>(static_cast<std::int64_t>(v));
  return t < v ? t + 1.0 : t;
}

// Exact squared forms of the reference's leaf tests sqrt(d2) < ze and sqrt(d2) <= zu (sqrt is
// correctly rounded, hence monotone): sqrt(d2) < z <=> d2 < sqrtBelow(z), and
// sqrt(d2) <= z <=> d2 <= sqrtAtMost(z), for every d2 >= 0. A few nextafter steps per beam.
// The neighbour of a finite double t >= 0 one step up (+1) or down (-1, t > 0): the bit
// patterns of non-negative doubles are ordered like their values.
inline double stepDouble(double t, int dir) {
  std::uint64_t b;
  std::memcpy(&b, &t, sizeof b);
  b = dir > 0 ? b + 1 : b - 1;
  std::memcpy(&t, &b, sizeof b);
  return t;
}
inline double nextUp(double t) { return stepDouble(t, 1); }
inline double nextDown(double t) { return stepDouble(t, -1); }
inline double sqrtBelow(double z) {  // smallest t >= 0 with sqrt(t) >= z
  if (!(z > 0.0)) return 0.0;
  double t = z * z;
  if (std::isinf(t)) return t;
  while (t > 0.0 && std::sqrt(nextDown(t)) >= z) t = nextDown(t);
  while (std::sqrt(t) < z) t = nextUp(t);
  return t;
}
inline double sqrtAtMost(double z) {  // largest t with sqrt(t) <= z; -1 when none
  if (!(z >= 0.0)) return -1.0;
  double t = z * z;
  if (std::isinf(t)) return t;
  if (t == 0.0) return 0.0;  // sqrt of the smallest subnormal exceeds any z whose square is 0
  while (std::sqrt(nextUp(t)) <= z) t = nextUp(t);
  while (t > 0.0 && std::sqrt(t) > z) t = nextDown(t);
  return t;
}

enum BeamKind : std::uint8_t { kInvalid = 0, kHit = 1, kClear = 2 };

// atan2 from an odd polynomial on [0, 1] (coefficients fitted for this project by reweighted
// least squares against std::atan; measured max error 2.5e-7 rad) and octant symmetry. Node
// classification only needs bearings up to a known error, which it pads by kFastAtanError.
constexpr double kFastAtanError = 1e-6;
inline double fastAtan2(double y, double x) {
  constexpr double kC[7] = {0.99999611591913118,  -0.33317382497041043, 0.19807947831023187,
                            -0.1323385017280396,  0.079633010601756773, -0.033612359910421385,
                            0.0068144960901458541};
  const double ax = std::fabs(x), ay = std::fabs(y);
  const double mx = std::max(ax, ay), mn = std::min(ax, ay);
  if (mx == 0.0) return 0.0;
  const double a = mn / mx, q = a * a;
  double r =
      a * (kC[0] + q * (kC[1] + q * (kC[2] + q * (kC[3] + q * (kC[4] + q * (kC[5] + q * kC[6]))))));
  if (ay > ax) r = 1.57079632679489661923 - r;
  if (x < 0) r = 3.14159265358979323846 - r;
  return y < 0 ? -r : r;
}

/// What classifying a square learned: its class and the beams whose sectors may meet it, which
/// its sub-squares and cells inherit (they lie inside it).
struct BoxInfo {
  CellClass cls = CellClass::kMixed;
  int jlo = 0, jhi = -1;  ///< beams whose sector may hold a point of the square (a superset)
  bool single = false;    ///< every point of the square lies in sector jlo (jlo == jhi), in the fan
  bool narrow = false;    ///< its directions and sectors span under pi / 2: the sub-squares and
                          ///< cells find theirs by testing the boundaries (no bearings)
  int slo = 0, shi = -1;  ///< narrow: the sectors that may hold a point of the square, with -1 and
                          ///< n standing for outside the fan, before boundary 0 / past boundary n
};

// Margin of the boundary-ray side tests, in radians (far above the rounding of the reference's
// bearings and of the boundary directions).
constexpr double kRayMargin = 1e-9;

/// Classes of a group of finest cells as bit masks (one bit per cell): E, O, and U for neither.
struct CellMasks {
  std::uint32_t e = 0, o = 0;
};

/// An axis-aligned square of the map frame, in metres.
struct Square {
  double x0, y0, x1, y1;
};

/// Everything about one scan that node and cell classification need. Reused between scans.
struct PreparedScan {
  double px = 0, py = 0, theta = 0;  // sensor pose
  double amin = 0, inc = 0;          // beam j at amin + j*inc (sensor frame), inc > 0
  double seam = 0;                   // bearings are normalised into [seam, seam + 2 pi)
  double res = 0;
  int n = 0;
  double reach = 0;           // max zU over beams
  std::vector<float> ranges;  // work copy (reordered when inc < 0)
  std::vector<std::uint8_t> kind;
  std::vector<double> ze, zu;
  std::vector<double> ze2, zu2;  // sq(ze), sq(zu): squares of the limits (see sq() below)
  std::vector<double> te2, tu2;  // leaf tests on d2 = rho^2 (cellAt): sqrtBelow(ze) (-1: invalid),
                                 // sqrtAtMost(zu) (-1: not a hit, so never O)
  double reach2 = 0;             // sq(reach)
  std::vector<double> min_ze, max_zu;      // sparse tables of ze2, zu2, level-major, n per level
  std::vector<int> invalid_prefix;         // invalid_prefix[j] = #invalid beams in [0, j)
  std::vector<std::uint64_t> hits;         // sorted cell keys of hit endpoints
  std::vector<std::int64_t> hit_x, hit_y;  // per beam: the cell of its endpoint (hit beams)
  double fast_guard = 0;                   // |t - (j + 1/2)| beyond which fastAtan2 gives lround(t)
  double seam_map = 0;                     // theta + seam reduced to [-pi, pi): the seam, map frame
  double inv_inc = 0, t_seam = 0;          // 1 / inc and (seam - amin) / inc
  std::vector<double> bnd_x, bnd_y;        // boundary k between sectors k-1 and k: unit direction

  static std::uint64_t cellKey(std::int64_t ix, std::int64_t iy) {
    return (static_cast<std::uint64_t>(ix + (std::int64_t{1} << 31)) << 32) ^
           static_cast<std::uint64_t>(iy + (std::int64_t{1} << 31));
  }

  double normalise(double bearing) const {
    return bearing - kTwoPi * std::floor((bearing - seam) / kTwoPi);
  }

  /// Class of the finest cell (ix, iy) of a square classified as `box`: O if a hit falls in it
  /// (O wins), else sampled at the cell centre with the sector model. The dense reference in
  /// test/core repeats this rule with std::atan2 cell by cell; this gives the same class faster:
  /// only beams of `box` can have their endpoint in the cell, and in a single-beam square the
  /// sector is known without any bearing.
  CellClass classifyCell(std::int64_t ix, std::int64_t iy, const BoxInfo& box) const {
    const double dx = (static_cast<double>(ix) + 0.5) * res - px;
    const double dy = (static_cast<double>(iy) + 0.5) * res - py;
    std::size_t ju;
    if (box.single) {
      ju = static_cast<std::size_t>(box.jlo);
      if (kind[ju] == kHit && hit_x[ju] == ix && hit_y[ju] == iy) return CellClass::kOccupied;
    } else {
      if (isHitCell(ix, iy, box)) return CellClass::kOccupied;
      const long j = box.narrow ? beamIn(dx, dy, box) : beamOf(dx, dy);
      if (j < 0 || j >= n) return CellClass::kUnknown;
      ju = static_cast<std::size_t>(j);
    }
    return cellAt(ju, dx * dx + dy * dy);
  }

  /// The sector model's class of a cell (not holding a hit) in sector j whose centre lies at
  /// squared distance d2: the reference's sqrt(d2) < ze (E), else hit and sqrt(d2) <= zu (O).
  CellClass cellAt(std::size_t j, double d2) const {
    return d2 < te2[j]    ? CellClass::kEmpty
           : d2 <= tu2[j] ? CellClass::kOccupied
                          : CellClass::kUnknown;
  }

  /// True when the cells of square `box` lie in few sectors, known without bearings (single, or
  /// narrow over at most kFewSectors): classify4x4() applies.
  static constexpr int kFewSectors = 32;
  static bool fewSectors(const BoxInfo& box) {
    return box.single || (box.narrow && box.shi - box.slo < kFewSectors);
  }

  /// Up to this many boundaries, beamIn() tests each one; beyond, it bisects.
  static constexpr int kLinearSectors = 4;

  /// classifyCell() for the 16 cells of the 4 x 4 square at (ix0, iy0) classified as `box`
  /// (fewSectors(box)), as masks (bit x + 4 y for cell (x, y)). Distances and cross products are
  /// separable over the grid's 4 columns and 4 rows, and the hits of the square's beams are
  /// gathered once.
  CellMasks classify4x4(std::int64_t ix0, std::int64_t iy0, const BoxInfo& box) const {
    // The reference's arithmetic: dx = (ix + 1/2) res - px, d2 = dx dx + dy dy.
    std::array<double, 4> dx, dy, dx2, dy2;
    for (std::size_t i = 0; i < 4; ++i) {
      dx[i] = (static_cast<double>(ix0 + static_cast<std::int64_t>(i)) + 0.5) * res - px;
      dy[i] = (static_cast<double>(iy0 + static_cast<std::int64_t>(i)) + 0.5) * res - py;
      dx2[i] = dx[i] * dx[i];
      dy2[i] = dy[i] * dy[i];
    }
    std::uint32_t hit = 0;  // a hit endpoint of the square's beams in the cell
    for (int j = box.jlo; j <= box.jhi; ++j) {
      const auto ju = static_cast<std::size_t>(j);
      if (kind[ju] != kHit) continue;
      const std::int64_t hx = hit_x[ju] - ix0, hy = hit_y[ju] - iy0;
      if (hx >= 0 && hx < 4 && hy >= 0 && hy < 4) hit |= 1u << (hx + 4 * hy);
    }
    CellMasks m;
    if (box.single) {  // one beam: distances alone
      const auto ju = static_cast<std::size_t>(box.jlo);
      const double te = te2[ju], tu = tu2[ju];
      std::uint32_t e = 0, o = 0;
      for (unsigned i = 0; i < 16; ++i) {
        const double d2 = dx2[i & 3] + dy2[i >> 2];
        e |= static_cast<std::uint32_t>(d2 < te) << i;
        o |= static_cast<std::uint32_t>(d2 <= tu) << i;
      }
      m.e = e & ~hit;
      m.o = (o & ~e) | hit;
      return m;
    }
    // A few sectors. Where the distance alone decides (E in every sector of the square, or U in
    // every one: outside sectors and invalid beams count as U), no sector is needed.
    double te_min = box.slo < 0 || box.shi > n - 1 ? -1.0 : std::numeric_limits<double>::infinity();
    double te_max = -1.0, tu_max = -1.0;
    for (int j = box.jlo; j <= box.jhi; ++j) {
      const auto ju = static_cast<std::size_t>(j);
      te_min = std::min(te_min, te2[ju]);
      te_max = std::max(te_max, te2[ju]);
      tu_max = std::max(tu_max, tu2[ju]);
    }
    m.o = hit;
    // Up to kLinearSectors boundaries, their cross products' two terms are separable too: the
    // same products beamIn() forms, computed once per row and column.
    const int nb = box.shi - box.slo;
    std::array<std::array<double, 4>, kLinearSectors> bxdy, bydx;
    if (nb <= kLinearSectors) {
      for (int b = 0; b < nb; ++b) {
        const auto ku = static_cast<std::size_t>(box.slo + 1 + b), bu = static_cast<std::size_t>(b);
        for (std::size_t t = 0; t < 4; ++t) {
          bxdy[bu][t] = bnd_x[ku] * dy[t];
          bydx[bu][t] = bnd_y[ku] * dx[t];
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
      if (j < 0 || j >= n) continue;  // outside the fan: U
      const CellClass cls = cellAt(static_cast<std::size_t>(j), d2);
      m.e |= static_cast<std::uint32_t>(cls == CellClass::kEmpty) << i;
      m.o |= static_cast<std::uint32_t>(cls == CellClass::kOccupied) << i;
    }
    return m;
  }

  /// True if a hit endpoint lies in cell (ix, iy) of square `box` (only its beams can).
  bool isHitCell(std::int64_t ix, std::int64_t iy, const BoxInfo& box) const {
    constexpr int kScanLimit = 8;
    if (box.jhi - box.jlo >= kScanLimit) {
      return std::binary_search(hits.begin(), hits.end(), cellKey(ix, iy));
    }
    for (int j = box.jlo; j <= box.jhi; ++j) {
      const auto ju = static_cast<std::size_t>(j);
      if (kind[ju] == kHit && hit_x[ju] == ix && hit_y[ju] == iy) return true;
    }
    return false;
  }

  /// lround((normalise(atan2(dy, dx) - theta) - amin) / inc), as the reference computes it: the
  /// polynomial atan2 decides unless its error could move the result across a rounding boundary
  /// or the seam, then std::atan2 does.
  long beamOf(double dx, double dy) const {
    const double off = offSeam(fastAtan2(dy, dx));
    const double u = off * inv_inc + t_seam + 0.5;  // lround(t) = floor(t + 1/2) off the halves
    const double f = fastFloor(u);
    if (u - f > fast_guard && u - f < 1.0 - fast_guard && off > kFastAtanError &&
        off < kTwoPi - kFastAtanError) {
      return static_cast<long>(f);
    }
    return std::lround((normalise(std::atan2(dy, dx) - theta) - amin) / inc);
  }

  // Sector boundaries by cross products. Within a narrow square's sectors (under pi / 2) the
  // side of a direction against boundary k is monotone in k, so the tests bisect. "Surely" means
  // by more than kRayMargin radians (tol = kRayMargin * (|dx| + |dy|) bounds that from above).

  /// Largest k in [lo, hi] such that (dx, dy) is surely past boundary k (lo when none is tested).
  int lastSurelyPast(double dx, double dy, double tol, int lo, int hi) const {
    while (lo < hi) {
      const int mid = lo + (hi - lo + 1) / 2;
      const auto m = static_cast<std::size_t>(mid);
      const bool past = bnd_x[m] * dy - bnd_y[m] * dx > tol;  // branch-free: a coin toss
      lo = past ? mid : lo;
      hi = past ? hi : mid - 1;
    }
    return lo;
  }
  /// Largest k in [lo, hi] such that (dx, dy) is not surely before boundary k (lo when none).
  int lastNotSurelyBefore(double dx, double dy, double tol, int lo, int hi) const {
    while (lo < hi) {
      const int mid = lo + (hi - lo + 1) / 2;
      const auto m = static_cast<std::size_t>(mid);
      const bool before = bnd_x[m] * dy - bnd_y[m] * dx < -tol;
      hi = before ? mid - 1 : hi;
      lo = before ? lo : mid;
    }
    return lo;
  }

  /// Returned by linearSector() when a boundary is too close to tell.
  static constexpr long kUnsure = std::numeric_limits<long>::min();
  /// The sector, among slo..slo + nb, of a direction whose cross product with boundary
  /// slo + 1 + b is cross(b): slo plus the boundaries it is surely past (by more than tol), if it
  /// is surely on one side of each and past none after one it is before; else kUnsure.
  template <typename Cross>
  static long linearSector(int slo, int nb, double tol, Cross cross) {
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
  long beamIn(double dx, double dy, const BoxInfo& box) const {
    const double tol = kRayMargin * (std::fabs(dx) + std::fabs(dy));
    if (box.shi - box.slo <= kLinearSectors) {
      const long j = linearSector(box.slo, box.shi - box.slo, tol, [&](std::size_t b) {
        const std::size_t ku = static_cast<std::size_t>(box.slo) + 1 + b;
        return bnd_x[ku] * dy - bnd_y[ku] * dx;
      });
      return j != kUnsure ? j : beamOf(dx, dy);
    }
    const int j = lastSurelyPast(dx, dy, tol, box.slo, box.shi);
    if (j < box.shi) {
      const auto m = static_cast<std::size_t>(j + 1);
      if (!(bnd_x[m] * dy - bnd_y[m] * dx < -tol)) return beamOf(dx, dy);
    }
    return j;
  }

  double queryMin(int lo, int hi) const {
    const int k = 31 - __builtin_clz(static_cast<unsigned>(hi - lo + 1));
    const std::size_t base = static_cast<std::size_t>(k) * static_cast<std::size_t>(n);
    return std::min(min_ze[base + static_cast<std::size_t>(lo)],
                    min_ze[base + static_cast<std::size_t>(hi - (1 << k) + 1)]);
  }
  double queryMax(int lo, int hi) const {
    const int k = 31 - __builtin_clz(static_cast<unsigned>(hi - lo + 1));
    const std::size_t base = static_cast<std::size_t>(k) * static_cast<std::size_t>(n);
    return std::max(max_zu[base + static_cast<std::size_t>(lo)],
                    max_zu[base + static_cast<std::size_t>(hi - (1 << k) + 1)]);
  }

  /// Squared distance limit, monotone in z: squares compare like the distances (-1 for z <= 0,
  /// which no distance is below). Squares spare a square root per test; at leaves the exact
  /// distance is kept, as the reference compares it.
  static double sq(double z) { return z > 0.0 ? z * z : -1.0; }

  /// Squared distance from the sensor to the nearest point of `sq` (0 when it holds the sensor).
  double nearest2(const Square& sq) const {
    const double nx = std::max(std::max(sq.x0 - px, 0.0), px - sq.x1);
    const double ny = std::max(std::max(sq.y0 - py, 0.0), py - sq.y1);
    return nx * nx + ny * ny;
  }

  /// Squared distance from the sensor to the farthest corner of `sq`.
  double farthest2(const Square& sq) const {
    const double fx = std::max(std::fabs(sq.x0 - px), std::fabs(sq.x1 - px));
    const double fy = std::max(std::fabs(sq.y0 - py), std::fabs(sq.y1 - py));
    return fx * fx + fy * fy;
  }

  /// The square of side 2^l cells at cell (ix0, iy0), in metres.
  Square square(int l, std::int64_t ix0, std::int64_t iy0) const {
    const double size = static_cast<double>(std::int64_t{1} << l) * res;
    const double x0 = static_cast<double>(ix0) * res, y0 = static_cast<double>(iy0) * res;
    return {x0, y0, x0 + size, y0 + size};
  }

  /// Class of the square of side 2^l cells at cell (ix0, iy0) inside a square classified as
  /// `parent`: a sub-square of a single-beam square needs ranges only.
  BoxInfo classifyBox(int l, std::int64_t ix0, std::int64_t iy0, const BoxInfo& parent) const {
    if (parent.single) {
      BoxInfo info = parent;
      info.cls = classifyInBeam(l, ix0, iy0, parent.jlo);
      return info;
    }
    if (parent.narrow) return classifyInRange(l, ix0, iy0, parent);
    return classifyBox(l, ix0, iy0);
  }

  /// Corners of square `sq` (not holding the sensor) that bound its bearing interval, counter-
  /// clockwise first (a) and last (b), as offsets from the sensor. Which corners they are follows
  /// from where the sensor lies: left / right / within in x, below / above / within in y.
  void extremeCorners(const Square& sq, double* ax, double* ay, double* bx, double* by) const {
    const double x0 = sq.x0, y0 = sq.y0, x1 = sq.x1, y1 = sq.y1;
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

  /// classifyBox() for a sub-square of a narrow square: its beams are those of the parent from
  /// the last boundary its first corner is surely past to the last one its last corner may be
  /// past (conservative both ways).
  BoxInfo classifyInRange(int l, std::int64_t ix0, std::int64_t iy0, const BoxInfo& parent) const {
    const Square sq = square(l, ix0, iy0);
    BoxInfo info = parent;
    double ax, ay, bx, by;
    extremeCorners(sq, &ax, &ay, &bx, &by);
    info.slo = lastSurelyPast(ax, ay, kRayMargin * (std::fabs(ax) + std::fabs(ay)), parent.slo,
                              parent.shi);
    info.shi = lastNotSurelyBefore(bx, by, kRayMargin * (std::fabs(bx) + std::fabs(by)), info.slo,
                                   parent.shi);
    info.jlo = std::max(info.slo, 0);
    info.jhi = std::min(info.shi, n - 1);
    const bool partial = info.slo < 0 || info.shi > n - 1;
    info.single = !partial && info.jlo == info.jhi;
    info.cls =
        info.jlo > info.jhi ? CellClass::kUnknown : rangeClass(sq, info.jlo, info.jhi, partial);
    return info;
  }

  /// Class of square `sq` whose cells lie in sectors jlo..jhi (`partial`: or outside the fan),
  /// from its distance range against the beams' limits.
  CellClass rangeClass(const Square& sq, int jlo, int jhi, bool partial) const {
    if (nearest2(sq) > queryMax(jlo, jhi)) return CellClass::kUnknown;
    if (farthest2(sq) < queryMin(jlo, jhi)) {
      const bool any_invalid = invalid_prefix[static_cast<std::size_t>(jhi) + 1] >
                               invalid_prefix[static_cast<std::size_t>(jlo)];
      return (partial || any_invalid) ? CellClass::kFreeOrUnknown : CellClass::kEmpty;
    }
    return CellClass::kMixed;
  }

  /// Class of a square that lies in sector j (not holding the sensor). Only beam j can put a hit
  /// in it, so the class follows from its distance range against ze[j], zu[j].
  CellClass classifyInBeam(int l, std::int64_t ix0, std::int64_t iy0, int j) const {
    const Square sq = square(l, ix0, iy0);
    const auto ju = static_cast<std::size_t>(j);
    if (nearest2(sq) > zu2[ju]) return CellClass::kUnknown;  // also invalid beams (zu2 = -1)
    if (farthest2(sq) < ze2[ju]) return CellClass::kEmpty;
    return kind[ju] == kClear ? CellClass::kFreeOrUnknown : CellClass::kMixed;
  }

  /// Class of the square of side 2^l cells at cell (ix0, iy0), conservative: kEmpty only if
  /// every cell in it is E, kUnknown only if every cell is U, kFreeOrUnknown only if no cell is O.
  BoxInfo classifyBox(int l, std::int64_t ix0, std::int64_t iy0) const {
    BoxInfo info;
    info.jlo = 0;
    info.jhi = n - 1;
    const Square sq = square(l, ix0, iy0);
    if (px >= sq.x0 && px <= sq.x1 && py >= sq.y0 && py <= sq.y1) return info;  // holds the sensor
    info.cls = CellClass::kUnknown;
    if (nearest2(sq) > reach2) return info;

    // Bearing interval of the square (convex, not holding the sensor: span < pi).
    double ax, ay, bx, by;
    extremeCorners(sq, &ax, &ay, &bx, &by);
    // Offsets past the seam, in [0, 2 pi); the square wraps the seam when the last is below the
    // first, and is then unwrapped.
    const double lo = offSeam(fastAtan2(ay, ax));
    double hi = offSeam(fastAtan2(by, bx));
    const bool straddles = hi < lo;
    if (straddles) hi += kTwoPi;
    // Beams j whose sector may hold a point of [lo, hi]: the cells' lround() lands in [jlo, jhi].
    auto beamRange = [&](double a_lo, double a_hi, long* jlo, long* jhi) {
      const double t_lo = (a_lo - kFastAtanError) * inv_inc + t_seam - 0.5 - kIndexSlack;
      const double t_hi = (a_hi + kFastAtanError) * inv_inc + t_seam + 0.5 + kIndexSlack;
      // Clamped to [-1, n] both ways: with a tiny beam step t can exceed any integer type.
      const double top = static_cast<double>(n);
      *jlo = static_cast<long>(fastCeil(std::min(std::max(t_lo, -1.0), top)));
      *jhi = static_cast<long>(fastFloor(std::max(std::min(t_hi, top), -1.0)));
    };
    long jlo, jhi;
    beamRange(lo, hi, &jlo, &jhi);
    const long slo = jlo, shi = jhi;  // in [-1, n]: -1 and n are the outside of the fan
    const bool partial = straddles || jlo < 0 || jhi > n - 1;
    jlo = std::max(jlo, 0L);
    jhi = std::min(jhi, static_cast<long>(n - 1));
    if (straddles) {
      long klo, khi;
      beamRange(lo - kTwoPi, hi - kTwoPi, &klo, &khi);
      klo = std::max(klo, 0L);
      khi = std::min(khi, static_cast<long>(n - 1));
      if (klo <= khi) {
        if (jlo <= jhi) {
          jlo = std::min(jlo, klo);  // union covered by its hull: conservative
          jhi = std::max(jhi, khi);
        } else {
          jlo = klo;
          jhi = khi;
        }
      }
    }
    if (jlo > jhi) return info;
    const int ilo = static_cast<int>(jlo), ihi = static_cast<int>(jhi);
    info.jlo = ilo;
    info.jhi = ihi;
    info.single = !partial && ilo == ihi;
    // Narrow, also across an edge of the fan (not the seam): every point and every boundary
    // between its sectors within pi / 2 of each other, so boundary side tests are monotone.
    info.narrow = !straddles && static_cast<double>(shi - slo + 1) * inc < 0.5 * kPi &&
                  (hi - lo) + inc < 0.5 * kPi;
    info.slo = static_cast<int>(slo);
    info.shi = static_cast<int>(shi);
    info.cls = rangeClass(sq, ilo, ihi, partial);
    return info;
  }

  /// A map-frame direction angle (from fastAtan2, in [-pi, pi]) as its sensor-frame bearing's
  /// offset past the seam, in [0, 2 pi). Within a few ulps of normalise() - seam.
  double offSeam(double map_angle) const {
    double v = map_angle - seam_map;
    if (v < 0.0) v += kTwoPi;
    if (v >= kTwoPi) v -= kTwoPi;
    return v;
  }
};

/// Validates the scan and fills `ps`. Beam counts go to `st`.
ScanStatus prepare(const MapParams& params, const Pose2& pose, const ScanView& scan,
                   PreparedScan* ps, IntegrateStats* st) {
  if (scan.count == 0 || scan.ranges == nullptr) return ScanStatus::kEmpty;
  const double n_beams = static_cast<double>(scan.count);
  if (!std::isfinite(scan.angle_min) || !std::isfinite(scan.angle_increment) ||
      scan.angle_increment == 0.0 || !std::isfinite(scan.range_min) || scan.range_min < 0.0 ||
      !(scan.range_max > scan.range_min) || std::isnan(scan.range_max) ||
      std::fabs(scan.angle_increment) * n_beams > kTwoPi + 1e-6 || scan.count > (1u << 24)) {
    return ScanStatus::kBadGeometry;
  }
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta)) {
    return ScanStatus::kBadPose;
  }
  const int n = static_cast<int>(scan.count);
  const auto nu = static_cast<std::size_t>(n);
  ps->n = n;
  ps->px = pose.x;
  ps->py = pose.y;
  ps->theta = pose.theta;
  ps->res = params.grid.resolution;
  ps->ranges.assign(scan.ranges, scan.ranges + n);
  if (scan.angle_increment > 0) {
    ps->amin = scan.angle_min;
    ps->inc = scan.angle_increment;
  } else {  // same beams, ascending bearings
    ps->amin = scan.angle_min + scan.angle_increment * (n_beams - 1.0);
    ps->inc = -scan.angle_increment;
    std::reverse(ps->ranges.begin(), ps->ranges.end());
  }
  const double amax = ps->amin + ps->inc * (n_beams - 1.0);
  ps->seam = 0.5 * (ps->amin + amax) - kPi;

  const double sensor_max = params.sensor.max_range > 0
                                ? std::min(params.sensor.max_range, scan.range_max)
                                : scan.range_max;
  const double half_band =
      0.5 * (params.sensor.band_width > 0 ? params.sensor.band_width : params.grid.resolution);
  const double clear = params.sensor.no_return_clear;
  const double inf = std::numeric_limits<double>::infinity();
  ps->kind.assign(nu, kInvalid);
  ps->ze.assign(nu, inf);
  ps->zu.assign(nu, -inf);
  ps->invalid_prefix.assign(nu + 1, 0);
  ps->hits.clear();
  ps->hit_x.assign(nu, 0);
  ps->hit_y.assign(nu, 0);
  ps->fast_guard = kFastAtanError / ps->inc + kIndexSlack;
  ps->seam_map = std::remainder(ps->theta + ps->seam, kTwoPi);
  ps->inv_inc = 1.0 / ps->inc;
  ps->t_seam = (ps->seam - ps->amin) / ps->inc;
  ps->bnd_x.resize(nu + 1);
  ps->bnd_y.resize(nu + 1);
  // Boundary k points along theta + amin + (k - 1/2) inc. Rotating by inc from a direction
  // computed with sin and cos every kBoundaryAnchor boundaries spares a sin and a cos per beam;
  // it drifts by under 1e-12 rad (4e-13 worst, measured for steps from 1e-6 to 2.1 rad), far
  // inside kRayMargin.
  constexpr std::size_t kBoundaryAnchor = 64;
  const double step_c = std::cos(ps->inc), step_s = std::sin(ps->inc);
  for (std::size_t k = 0; k <= nu; ++k) {
    if (k % kBoundaryAnchor == 0) {
      const double b = ps->theta + ps->amin + (static_cast<double>(k) - 0.5) * ps->inc;
      ps->bnd_x[k] = std::cos(b);
      ps->bnd_y[k] = std::sin(b);
    } else {
      const double c = ps->bnd_x[k - 1], s = ps->bnd_y[k - 1];
      ps->bnd_x[k] = c * step_c - s * step_s;
      ps->bnd_y[k] = s * step_c + c * step_s;
    }
  }
  ps->reach = 0.0;
  for (std::size_t j = 0; j < nu; ++j) {
    const double z = ps->ranges[j];
    std::uint8_t kind = kInvalid;
    if (std::isnan(z) || z == -inf || z <= 0.0 || z < scan.range_min) {
      ++st->beams_invalid;
    } else if (z >= sensor_max) {  // +inf and out-of-range readings: no return (REP 117)
      ++st->beams_no_return;
      if (clear > 0) {
        kind = kClear;
        ps->ze[j] = clear;
        ps->zu[j] = clear;
      }
    } else {
      ++st->beams_hit;
      kind = kHit;
      ps->ze[j] = z - half_band;
      ps->zu[j] = z + half_band;
      const double bearing = pose.theta + (ps->amin + static_cast<double>(j) * ps->inc);
      const double ex = pose.x + z * std::cos(bearing), ey = pose.y + z * std::sin(bearing);
      ps->hit_x[j] = static_cast<std::int64_t>(std::floor(ex / ps->res));
      ps->hit_y[j] = static_cast<std::int64_t>(std::floor(ey / ps->res));
      ps->hits.push_back(PreparedScan::cellKey(ps->hit_x[j], ps->hit_y[j]));
    }
    ps->kind[j] = kind;
    if (kind != kInvalid) ps->reach = std::max(ps->reach, ps->zu[j]);
    ps->invalid_prefix[j + 1] = ps->invalid_prefix[j] + (kind == kInvalid ? 1 : 0);
  }
  if (ps->invalid_prefix[nu] == n) return ScanStatus::kNoValidBeam;
  std::sort(ps->hits.begin(), ps->hits.end());
  ps->hits.erase(std::unique(ps->hits.begin(), ps->hits.end()), ps->hits.end());

  // Sparse tables: level k holds min/max over [j, j + 2^k).
  int levels = 1;
  while ((1 << levels) <= n) ++levels;
  ps->min_ze.resize(static_cast<std::size_t>(levels) * nu);
  ps->max_zu.resize(static_cast<std::size_t>(levels) * nu);
  ps->ze2.resize(nu);
  ps->zu2.resize(nu);
  ps->te2.resize(nu);
  ps->tu2.resize(nu);
  for (std::size_t j = 0; j < nu; ++j) {
    ps->ze2[j] = PreparedScan::sq(ps->ze[j]);
    ps->zu2[j] = PreparedScan::sq(ps->zu[j]);
    ps->te2[j] = ps->kind[j] == kInvalid ? -1.0 : sqrtBelow(ps->ze[j]);
    ps->tu2[j] = ps->kind[j] == kHit ? sqrtAtMost(ps->zu[j]) : -1.0;
  }
  ps->reach2 = PreparedScan::sq(ps->reach);
  std::copy(ps->ze2.begin(), ps->ze2.end(), ps->min_ze.begin());
  std::copy(ps->zu2.begin(), ps->zu2.end(), ps->max_zu.begin());
  for (int k = 1; k < levels; ++k) {
    const std::size_t base = static_cast<std::size_t>(k) * nu, prev = base - nu;
    const std::size_t half = std::size_t{1} << (k - 1);
    for (std::size_t j = 0; j + (std::size_t{1} << k) <= nu; ++j) {
      ps->min_ze[base + j] = std::min(ps->min_ze[prev + j], ps->min_ze[prev + j + half]);
      ps->max_zu[base + j] = std::max(ps->max_zu[prev + j], ps->max_zu[prev + j + half]);
    }
  }
  return ScanStatus::kOk;
}

/// Policy constants for one scan.
struct PolicyConsts {
  double odd_occ, odd_emp, a, g, lo, hi, unchanged_tol;
};

template <PolicyType P>
inline double applyPolicy(const PolicyConsts& pc, CellClass cls, double x) {
  const double o = cls == CellClass::kOccupied ? pc.odd_occ : pc.odd_emp;
  if constexpr (P == PolicyType::kNone) return x + o;
  if constexpr (P == PolicyType::kMax) return std::max(x, o);
  if constexpr (P == PolicyType::kClamp) return std::min(std::max(x + o, pc.lo), pc.hi);
  if constexpr (P == PolicyType::kForget) return pc.a * x + pc.g * o;
  if constexpr (P == PolicyType::kClampLower) return std::max(x + o, pc.lo);
  if constexpr (P == PolicyType::kClampUpper) return std::min(x + o, pc.hi);
  return x;
}

/// The E update is affine on every cell (so exact on a block average, details untouched or
/// scaled): none, forget, and clamp_upper (x + odd_emp < x <= hi never reaches the bound).
template <PolicyType P>
constexpr bool kAffineEmpty =
    P == PolicyType::kNone || P == PolicyType::kForget || P == PolicyType::kClampUpper;

template <PolicyType P>
class Integrator {
 public:
  Integrator(WaveletMap::Impl& impl, const PreparedScan& ps, const PolicyConsts& pc)
      : impl_(impl), ps_(ps), pc_(pc), lazy_(impl.params.lazy_forgetting) {}

  std::uint64_t visited() const { return visited_; }

  void integrateBlock(Block& b, std::int64_t ix0, std::int64_t iy0, const BoxInfo& box) {
    const int L = impl_.levels;
    Node* root = b.has_root ? &b.root : nullptr;
    bool all = b.known_all, any = b.known_any;
    b.s += processSlot(
        root, box, L, ix0, iy0, b.s, &all, &any, [&](const Node& m) { impl_.installRoot(&b, m); },
        [&]() { impl_.removeRoot(&b); });
    b.known_all = all;
    b.known_any = any;
  }

 private:
  // Updates one slot (a node at level l >= 1, or a uniform block when `node` is null) classified
  // as `box` whose average is s; returns the change of that average. `all`/`any` are the slot's
  // knowledge bits, updated. install(m) stores a new node, remove() deletes the existing one.
  template <typename Install, typename Remove>
  double processSlot(Node* node, const BoxInfo& box, int l, std::int64_t ix0, std::int64_t iy0,
                     double s, bool* all, bool* any, Install install, Remove remove) {
    return updateSlot(node, box.cls, s, all, any, install, remove,
                      [&](Node& m) { return visitNode(m, box, l, ix0, iy0, s); });
  }

  // The rules of one slot of class `cls` (U skipped, E at the slot's own scale, the section 3.4
  // skip); descend(m) updates the slot's node m (the stored one, or a temporary uniform one) when
  // the slot must be refined, and returns the change of its average.
  template <typename Install, typename Remove, typename Descend>
  double updateSlot(Node* node, CellClass cls, double s, bool* all, bool* any, Install install,
                    Remove remove, Descend descend) {
    switch (cls) {
      case CellClass::kUnknown:
        return 0.0;
      case CellClass::kEmpty:
        if (node == nullptr) {  // uniform block: exact for every policy
          *all = *any = true;
          return applyPolicy<P>(pc_, CellClass::kEmpty, s) - s;
        }
        if (kAffineEmpty<P> && node->known_all == 0xF) {
          if constexpr (P == PolicyType::kForget) {
            if (lazy_) {
              // ALGORITHM.md 6.3: the multiplicative part waits in the tag, the additive part
              // reaches the parent now through the returned change of the average.
              impl_.addPending(*node, 1);
              if (node->k >= impl_.k_star) remove();  // section 6.5: subtree negligible
            } else {
              scaleSubtree(*node);
            }
          }
          *all = *any = true;
          return applyPolicy<P>(pc_, CellClass::kEmpty, s) - s;
        }
        break;  // detail below (non-affine policy) or knowledge still to record: descend
      case CellClass::kFreeOrUnknown:
        // ALGORITHM.md 3.4: the E part would not change a uniform, fully known block.
        if (node == nullptr && *all &&
            std::fabs(applyPolicy<P>(pc_, CellClass::kEmpty, s) - s) <= pc_.unchanged_tol) {
          return 0.0;
        }
        break;
      default:
        break;
    }
    Node tmp = WaveletMap::Impl::uniformSlot(*all, *any);
    Node& m = node ? *node : tmp;
    const double ds = descend(m);
    impl_.settleSlot(m, node != nullptr, all, any, install, remove);
    return ds;
  }

  // Descends through node n (level l, average s): flushes its tag (F1), updates its 4 children,
  // folds their average changes into n's details with one forward Haar step.
  double visitNode(Node& n, const BoxInfo& box, int l, std::int64_t ix0, std::int64_t iy0,
                   double s) {
    ++visited_;
    impl_.flush(n);
    // The children are read after the (long) classification: fetch them meanwhile.
    if (n.children != 0) impl_.pool.prefetch(n.children);
    if (l == 1) return visitLeafParent(n, box, ix0, iy0, s);
    if (l == 2 && ps_.fewSectors(box)) return visitLevel2(n, box, ix0, iy0, s);
    const std::array<double, 4> c = haar::backward(s, n.d);
    std::array<double, 4> delta{};
    const std::int64_t half = std::int64_t{1} << (l - 1);
    for (int q = 0; q < 4; ++q) {
      const auto qu = static_cast<std::size_t>(q);
      const std::int64_t cx = ix0 + ((q & 1) ? half : 0), cy = iy0 + ((q & 2) ? half : 0);
      const auto bit = static_cast<std::uint8_t>(1u << q);
      const BoxInfo child_box = ps_.classifyBox(l - 1, cx, cy, box);
      ++visited_;
      if (child_box.cls == CellClass::kUnknown) continue;
      Node* ch = impl_.hasChild(n, q) ? &impl_.child(n, q) : nullptr;
      bool all = (n.known_all & bit) != 0, any = (n.known_any & bit) != 0;
      delta[qu] = processSlot(
          ch, child_box, l - 1, cx, cy, c[qu], &all, &any,
          [&](const Node& m) { impl_.installChild(n, q, m); }, [&]() { impl_.removeChild(n, q); });
      detail::setBit(&n.known_all, bit, all);
      detail::setBit(&n.known_any, bit, any);
    }
    return foldChanges(n, delta);
  }

  // A level-1 node: its children are finest cells.
  double visitLeafParent(Node& n, const BoxInfo& box, std::int64_t ix0, std::int64_t iy0,
                         double s) {
    CellMasks cells;
    for (unsigned q = 0; q < 4; ++q) {
      const CellClass cls = ps_.classifyCell(ix0 + static_cast<std::int64_t>(q & 1),
                                             iy0 + static_cast<std::int64_t>(q >> 1), box);
      cells.e |= static_cast<std::uint32_t>(cls == CellClass::kEmpty) << q;
      cells.o |= static_cast<std::uint32_t>(cls == CellClass::kOccupied) << q;
    }
    return updateCells(n, cells, s);
  }

  // Applies the policy to the 4 finest cells of level-1 node n (average s, tag flushed), cell q
  // E or O by bit q of `cells` (U when in neither); returns the change of n's average.
  double updateCells(Node& n, const CellMasks& cells, double s) {
    visited_ += 4;
    const std::array<double, 4> c = haar::backward(s, n.d);
    std::array<double, 4> delta{};
    for (std::size_t q = 0; q < 4; ++q) {
      if ((cells.e >> q) & 1u) {
        delta[q] = applyPolicy<P>(pc_, CellClass::kEmpty, c[q]) - c[q];
      } else if ((cells.o >> q) & 1u) {
        delta[q] = applyPolicy<P>(pc_, CellClass::kOccupied, c[q]) - c[q];
      }
    }
    const auto known = static_cast<std::uint8_t>(cells.e | cells.o);
    n.known_all = static_cast<std::uint8_t>(n.known_all | known);
    n.known_any = static_cast<std::uint8_t>(n.known_any | known);
    return foldChanges(n, delta);
  }

  // A level-2 node (4 x 4 finest cells, tag flushed): its 16 cells are classified together
  // (cheaply when the square lies in one or a few sectors) and each level-1 child slot takes the
  // class of its 4 cells, exactly, instead of a conservative square test of its own.
  double visitLevel2(Node& n, const BoxInfo& box, std::int64_t ix0, std::int64_t iy0, double s) {
    const CellMasks cells = ps_.classify4x4(ix0, iy0, box);  // cell (x, y) at bit x + 4 y
    const std::array<double, 4> c = haar::backward(s, n.d);
    std::array<double, 4> delta{};
    for (int q = 0; q < 4; ++q) {
      ++visited_;
      const auto qu = static_cast<std::size_t>(q);
      // The slot's cells (x, y), x, y in {0, 1}, as bits x + 2 y.
      const unsigned shift = static_cast<unsigned>((q & 1) * 2 + (q >> 1) * 8);
      const CellMasks cc{quad(cells.e >> shift), quad(cells.o >> shift)};
      const CellClass slot = slotClass(cc);
      if (slot == CellClass::kUnknown) continue;
      const auto bit = static_cast<std::uint8_t>(1u << q);
      Node* ch = impl_.hasChild(n, q) ? &impl_.child(n, q) : nullptr;
      bool all = (n.known_all & bit) != 0, any = (n.known_any & bit) != 0;
      delta[qu] = updateSlot(
          ch, slot, c[qu], &all, &any, [&](const Node& m) { impl_.installChild(n, q, m); },
          [&]() { impl_.removeChild(n, q); },
          [&](Node& m) {
            ++visited_;
            impl_.flush(m);
            return updateCells(m, cc, c[qu]);
          });
      detail::setBit(&n.known_all, bit, all);
      detail::setBit(&n.known_any, bit, any);
    }
    return foldChanges(n, delta);
  }

  // Bits 0, 1, 4, 5 of a 4 x 4 mask (a 2 x 2 corner) as bits 0..3.
  static std::uint32_t quad(std::uint32_t bits) { return (bits & 3u) | ((bits >> 2) & 0xCu); }

  // The exact class of a 2 x 2 square from its cells' classes.
  static CellClass slotClass(const CellMasks& cc) {
    if (cc.o != 0) return CellClass::kMixed;
    if (cc.e == 0xFu) return CellClass::kEmpty;
    return cc.e == 0 ? CellClass::kUnknown : CellClass::kFreeOrUnknown;
  }

  // Folds the children's average changes into n's details (one forward Haar step); returns the
  // change of n's average.
  static double foldChanges(Node& n, const std::array<double, 4>& delta) {
    haar::Details<double> dd;
    const double ds = haar::forward(delta, &dd);
    for (int i = 0; i < 3; ++i) {
      n.d[i] = static_cast<float>(static_cast<double>(n.d[i]) + dd[static_cast<std::size_t>(i)]);
    }
    return ds;
  }

  // Eager forgetting (lazy tags off): every detail of the subtree times a, now.
  void scaleSubtree(Node& n) {
    ++visited_;
    const auto a = static_cast<float>(pc_.a);
    for (float& d : n.d) d *= a;
    if (n.children == 0) return;
    for (int q = 0; q < 4; ++q) {
      if (impl_.hasChild(n, q)) scaleSubtree(impl_.child(n, q));
    }
  }

  WaveletMap::Impl& impl_;
  const PreparedScan& ps_;
  const PolicyConsts pc_;
  const bool lazy_;
  std::uint64_t visited_ = 0;
};

template <PolicyType P>
std::uint64_t integrateAll(WaveletMap::Impl& impl, const PreparedScan& ps, IntegrateStats* st) {
  const MapParams& p = impl.params;
  const PolicyConsts pc{p.sensor.odd_occ,
                        p.sensor.odd_emp,
                        impl.a,
                        P == PolicyType::kForget ? p.policy.gamma : 0.0,
                        p.policy.clamp_min,
                        p.policy.clamp_max,
                        std::max(p.skip_tolerance, kUnchangedFloor)};
  Integrator<P> integrator(impl, ps, pc);
  const int L = impl.levels;
  const double block_size = static_cast<double>(std::int64_t{1} << L) * ps.res;
  const auto lo_x = static_cast<std::int64_t>(std::floor((ps.px - ps.reach) / block_size));
  const auto hi_x = static_cast<std::int64_t>(std::floor((ps.px + ps.reach) / block_size));
  const auto lo_y = static_cast<std::int64_t>(std::floor((ps.py - ps.reach) / block_size));
  const auto hi_y = static_cast<std::int64_t>(std::floor((ps.py + ps.reach) / block_size));
  std::uint64_t visited = 0;
  for (std::int64_t by = lo_y; by <= hi_y; ++by) {
    for (std::int64_t bx = lo_x; bx <= hi_x; ++bx) {
      const std::int64_t ix0 = detail::scaleUp(bx, L), iy0 = detail::scaleUp(by, L);
      const BoxInfo box = ps.classifyBox(L, ix0, iy0);
      ++visited;
      if (box.cls == CellClass::kUnknown) continue;
      ++st->blocks_touched;
      integrator.integrateBlock(impl.getOrCreateBlock(bx, by), ix0, iy0, box);
    }
  }
  return visited + integrator.visited();
}

}  // namespace

IntegrateStats WaveletMap::integrate(const Pose2& sensor_pose, const ScanView& scan) {
  IntegrateStats st;
  thread_local PreparedScan ps;
  st.status = prepare(impl_->params, sensor_pose, scan, &ps, &st);
  if (st.status != ScanStatus::kOk) {
    impl_->nodes_visited_last = 0;
    return st;
  }
  std::uint64_t visited = 0;
  switch (impl_->params.policy.type) {
    case PolicyType::kNone:
      visited = integrateAll<PolicyType::kNone>(*impl_, ps, &st);
      break;
    case PolicyType::kMax:
      visited = integrateAll<PolicyType::kMax>(*impl_, ps, &st);
      break;
    case PolicyType::kClamp:
      visited = integrateAll<PolicyType::kClamp>(*impl_, ps, &st);
      break;
    case PolicyType::kForget:
      visited = integrateAll<PolicyType::kForget>(*impl_, ps, &st);
      break;
    case PolicyType::kClampLower:
      visited = integrateAll<PolicyType::kClampLower>(*impl_, ps, &st);
      break;
    case PolicyType::kClampUpper:
      visited = integrateAll<PolicyType::kClampUpper>(*impl_, ps, &st);
      break;
  }
  st.nodes_visited = visited;
  impl_->nodes_visited_last = visited;
  return st;
}

}  // namespace wavog
