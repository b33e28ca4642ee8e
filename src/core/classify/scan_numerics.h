// Numerical helpers of the scan classification: floor / ceil without libm, the exact squared forms
// of the reference's leaf distance tests, a polynomial atan2 with a stated error, and the margins
// that keep every fast decision conservative. Not installed; included only by src/core/*.
#ifndef WAVOG_MAPPING_SRC_CORE_CLASSIFY_SCAN_NUMERICS_H_
#define WAVOG_MAPPING_SRC_CORE_CLASSIFY_SCAN_NUMERICS_H_

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#if defined(__SSE2__)
#include <emmintrin.h>  // x86-64's baseline: no runtime dispatch needed
#endif

namespace wavog {
namespace detail {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;
/// Slack on beam-index bounds (in beams) so rounding in atan2 never misses a beam.
constexpr double kIndexSlack = 1e-6;
/// Error bound of fastAtan2 (rad), padded: measured max error 2.5e-7 rad.
constexpr double kFastAtanError = 1e-6;
/// Margin of the boundary-ray side tests, in radians (far above the rounding of the reference's
/// bearings and of the boundary directions).
constexpr double kRayMargin = 1e-9;

/// floor / ceil without a libm call (x86-64's baseline has no rounding instruction). Magnitudes
/// of 2^52 and more are integers already; NaN goes to std::floor / std::ceil.
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

/// The neighbour of a finite double t >= 0 one step up (+1) or down (-1, t > 0): the bit
/// patterns of non-negative doubles are ordered like their values.
inline double stepDouble(double t, int dir) {
  std::uint64_t b;
  std::memcpy(&b, &t, sizeof b);
  b = dir > 0 ? b + 1 : b - 1;
  std::memcpy(&t, &b, sizeof b);
  return t;
}
inline double nextUp(double t) { return stepDouble(t, 1); }
inline double nextDown(double t) { return stepDouble(t, -1); }

/// Exact squared forms of the reference's leaf tests sqrt(d2) < ze and sqrt(d2) <= zu (sqrt is
/// correctly rounded, hence monotone): sqrt(d2) < z <=> d2 < sqrtBelow(z), and
/// sqrt(d2) <= z <=> d2 <= sqrtAtMost(z), for every d2 >= 0. A few nextafter steps per beam.
/// sqrtBelow: the smallest t >= 0 with sqrt(t) >= z.
inline double sqrtBelow(double z) {
  if (!(z > 0.0)) return 0.0;
  double t = z * z;
  if (std::isinf(t)) return t;
  while (t > 0.0 && std::sqrt(nextDown(t)) >= z) t = nextDown(t);
  while (std::sqrt(t) < z) t = nextUp(t);
  return t;
}
/// sqrtAtMost: the largest t with sqrt(t) <= z; -1 when none.
inline double sqrtAtMost(double z) {
  if (!(z >= 0.0)) return -1.0;
  double t = z * z;
  if (std::isinf(t)) return t;
  if (t == 0.0) return 0.0;  // sqrt of the smallest subnormal exceeds any z whose square is 0
  while (std::sqrt(nextUp(t)) <= z) t = nextUp(t);
  while (t > 0.0 && std::sqrt(t) > z) t = nextDown(t);
  return t;
}

/// Squared distance limit, monotone in z: squares compare like the distances (-1 for z <= 0,
/// which no distance is below). Squares spare a square root per test of a square; at leaves the
/// exact thresholds above are used, as the reference compares distances.
inline double squaredLimit(double z) { return z > 0.0 ? z * z : -1.0; }

/// atan2 from an odd polynomial on [0, 1] (coefficients fitted for this project by reweighted
/// least squares against std::atan; measured max error 2.5e-7 rad) and octant symmetry. Node
/// classification only needs bearings up to a known error, which it pads by kFastAtanError.
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

/// Bit i set where a[i] < b[i] (Strict) or a[i] <= b[i], for 16 doubles (NaN: clear). With SSE2
/// a compare and a movemask per two (GCC does not pack compare results into bits by itself).
template <bool Strict>
inline std::uint32_t compareMask16(const double* a, const double* b) {
  std::uint32_t m = 0;
#if defined(__SSE2__)
  for (int i = 0; i < 16; i += 2) {
    const __m128d x = _mm_loadu_pd(a + i), y = _mm_loadu_pd(b + i);
    const __m128d c = Strict ? _mm_cmplt_pd(x, y) : _mm_cmple_pd(x, y);
    m |= static_cast<std::uint32_t>(_mm_movemask_pd(c)) << i;
  }
#else
  for (int i = 0; i < 16; ++i) {
    m |= static_cast<std::uint32_t>(Strict ? a[i] < b[i] : a[i] <= b[i]) << i;
  }
#endif
  return m;
}

/// The table buckets of a 4 x 4 group by the separable quotient: bucket[x + 4 y] =
/// int32((nc[x] + nr[y]) / (dc[x] + dr[y])) & mask (truncated; the quotients lie far inside the
/// int32 range). SSE2: a row of 4 cells in two divisions, a conversion and a mask, instead of the
/// shuffles GCC makes of the 16-cell loop; the same IEEE operations, so the same buckets.
inline void quotientBuckets16(const double* nc, const double* nr, const double* dc,
                              const double* dr, std::uint32_t mask, std::uint32_t* bucket) {
#if defined(__SSE2__)
  const __m128d n01 = _mm_loadu_pd(nc), n23 = _mm_loadu_pd(nc + 2);
  const __m128d d01 = _mm_loadu_pd(dc), d23 = _mm_loadu_pd(dc + 2);
  const __m128i m = _mm_set1_epi32(static_cast<int>(mask));
  for (int y = 0; y < 4; ++y) {
    const __m128d ny = _mm_set1_pd(nr[y]), dy = _mm_set1_pd(dr[y]);
    const __m128i lo = _mm_cvttpd_epi32(_mm_div_pd(_mm_add_pd(n01, ny), _mm_add_pd(d01, dy)));
    const __m128i hi = _mm_cvttpd_epi32(_mm_div_pd(_mm_add_pd(n23, ny), _mm_add_pd(d23, dy)));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(bucket + 4 * y),
                     _mm_and_si128(_mm_unpacklo_epi64(lo, hi), m));
  }
#else
  for (int i = 0; i < 16; ++i) {
    const double v = (nc[i & 3] + nr[i >> 2]) / (dc[i & 3] + dr[i >> 2]);
    bucket[i] = static_cast<std::uint32_t>(static_cast<std::int32_t>(v)) & mask;
  }
#endif
}

/// Bit i set where v[i] < 0, for 16 int32.
inline std::uint32_t negativeMask16(const std::int32_t* v) {
  std::uint32_t m = 0;
#if defined(__SSE2__)
  for (int i = 0; i < 16; i += 4) {
    const __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(v + i));
    m |= static_cast<std::uint32_t>(_mm_movemask_ps(_mm_castsi128_ps(x))) << i;
  }
#else
  for (int i = 0; i < 16; ++i) m |= static_cast<std::uint32_t>(v[i] < 0) << i;
#endif
  return m;
}

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_CLASSIFY_SCAN_NUMERICS_H_
