// One 2x2 Haar step, its inverse and the single-child forms (ALGORITHM.md section 2.1).
// Normalisation, stated once for the whole package: children v0=v(0,0), v1=v(1,0), v2=v(0,1),
// v3=v(1,1) (child index q = ix + 2*iy) map to
//   s = (v0+v1+v2+v3)/4, dx = ((v1+v3)-(v0+v2))/2, dy = ((v2+v3)-(v0+v1))/2, dxy = (v0+v3)-(v1+v2)
// and back to v_q = s + sx*dx/2 + sy*dy/2 + sx*sy*dxy/4 with sx = +1 iff ix = 1, sy = +1 iff iy = 1.
// s is the plain mean log-odds of the block, so a coarse level is itself an occupancy map.
#ifndef WAVOG_MAPPING_CORE_HAAR_H_
#define WAVOG_MAPPING_CORE_HAAR_H_

#include <array>

namespace wavog {
namespace haar {

/// Detail coefficients of one node: {dx, dy, dxy}.
template <typename T>
using Details = std::array<T, 3>;

/// Sign of the x (resp. y) offset of child q: -1 or +1.
constexpr int sx(int q) { return (q & 1) ? 1 : -1; }
constexpr int sy(int q) { return (q & 2) ? 1 : -1; }

/// Forward step: 4 children values -> average and details.
template <typename T>
inline T forward(const std::array<T, 4>& v, Details<T>* d) {
  (*d)[0] = ((v[1] + v[3]) - (v[0] + v[2])) / T(2);
  (*d)[1] = ((v[2] + v[3]) - (v[0] + v[1])) / T(2);
  (*d)[2] = (v[0] + v[3]) - (v[1] + v[2]);
  return (v[0] + v[1] + v[2] + v[3]) / T(4);
}

/// Inverse for one child (BackwardSingleChild): average of child q.
template <typename T, typename D>
inline T backwardChild(T s, const D& d, int q) {
  const T fx = T(sx(q)), fy = T(sy(q));
  return s + fx * T(d[0]) / T(2) + fy * T(d[1]) / T(2) + fx * fy * T(d[2]) / T(4);
}

/// Full inverse: average and details -> the 4 children's averages.
template <typename T, typename D>
inline std::array<T, 4> backward(T s, const D& d) {
  const T hx = T(d[0]) / T(2), hy = T(d[1]) / T(2), q4 = T(d[2]) / T(4);
  return {s - hx - hy + q4, s + hx - hy - q4, s - hx + hy - q4, s + hx + hy + q4};
}

/// Single-child forward step (ForwardSingleChild): adding `delta` to child q's average changes
/// the parent's average by the return value and its details by *dd.
template <typename T>
inline T forwardSingleChild(T delta, int q, Details<T>* dd) {
  const T fx = T(sx(q)), fy = T(sy(q));
  (*dd)[0] = fx * delta / T(2);
  (*dd)[1] = fy * delta / T(2);
  (*dd)[2] = fx * fy * delta;
  return delta / T(4);
}

}  // namespace haar
}  // namespace wavog

#endif  // WAVOG_MAPPING_CORE_HAAR_H_
