// A tile's observed cells updated in one loop (storage/tile.h, Integrator::visitTile): the
// policy shifted to the stored values (update_policy.h: ShiftedPolicy), every stored value kept
// within the file bound. Float tiles (the bounded policies) go four cells an instruction in SSE2,
// row by row, in float (eight cells an instruction where the CPU runs AVX2); double tiles (the
// unbounded ones) cell by cell in double. Returns the sum of the changes of the stored values (in
// double: the tree above holds the tile's mean).
// Not installed; included only by src/core/update/quadtree_update.h.
#ifndef WAVOG_MAPPING_SRC_CORE_UPDATE_TILE_UPDATE_H_
#define WAVOG_MAPPING_SRC_CORE_UPDATE_TILE_UPDATE_H_

#include <cstdint>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "storage/tile.h"
#include "update/tile_update_avx2.h"
#include "update/update_policy.h"

namespace wavog {
namespace detail {

/// Double tiles, and float ones without SSE2: the cells of `e` (E) and `o` (O), one by one.
template <PolicyType P, typename Tile>
inline double updateTileCells(const ShiftedPolicy& sp, Tile* t, std::uint64_t e, std::uint64_t o) {
  using T = std::remove_reference_t<decltype(t->v[0])>;
  double sum = 0.0;
  const auto update = [&](unsigned i, CellClass cls) {
    const double was = static_cast<double>(t->v[i]);
    t->v[i] = storedValue<T>(applyShifted<P>(sp, cls, was));
    sum += static_cast<double>(t->v[i]) - was;
  };
  for (std::uint64_t m = e; m != 0; m &= m - 1) update(__builtin_ctzll(m), CellClass::kEmpty);
  for (std::uint64_t m = o; m != 0; m &= m - 1) {
    update(__builtin_ctzll(m), CellClass::kOccupied);
  }
  return sum;
}

#if defined(__SSE2__)
namespace tile_sse {

/// All-ones float lanes for each four bits (bit 0: the lowest lane).
struct LaneMasks {
  alignas(16) std::uint32_t m[16][4]{};
  constexpr LaneMasks() {
    for (unsigned b = 0; b < 16; ++b) {
      for (unsigned l = 0; l < 4; ++l) m[b][l] = ((b >> l) & 1u) ? 0xFFFFFFFFu : 0u;
    }
  }
};
inline constexpr LaneMasks kLaneMasks{};
/// The lanes of the four bits of `bits`.
inline __m128 lanes(unsigned bits) {
  return _mm_load_ps(reinterpret_cast<const float*>(kLaneMasks.m[bits & 15u]));
}
/// m ? a : b, lane by lane.
inline __m128 select(__m128 m, __m128 a, __m128 b) {
  return _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b));
}

/// The policy's constants as float lanes.
struct Consts {
  __m128 odd_occ, odd_emp, lo, hi, a, add_occ, add_emp, bound;
  explicit Consts(const ShiftedPolicy& sp)
      : odd_occ(_mm_set1_ps(static_cast<float>(sp.odd_occ))),
        odd_emp(_mm_set1_ps(static_cast<float>(sp.odd_emp))),
        lo(_mm_set1_ps(static_cast<float>(sp.lo))),
        hi(_mm_set1_ps(static_cast<float>(sp.hi))),
        a(_mm_set1_ps(static_cast<float>(sp.a))),
        add_occ(_mm_set1_ps(static_cast<float>(sp.add_occ))),
        add_emp(_mm_set1_ps(static_cast<float>(sp.add_emp))),
        bound(_mm_set1_ps(kMaxStoredFloat)) {}
};

/// applyShifted<P>() of four cells v, O where `occ` is set, in float, within the bound.
template <PolicyType P>
inline __m128 policy(const Consts& c, __m128 v, __m128 occ) {
  const __m128 odd = select(occ, c.odd_occ, c.odd_emp);
  __m128 r = v;
  if constexpr (P == PolicyType::kNone) r = _mm_add_ps(v, odd);
  if constexpr (P == PolicyType::kMax) r = _mm_max_ps(v, odd);
  if constexpr (P == PolicyType::kClamp) r = _mm_min_ps(_mm_max_ps(_mm_add_ps(v, odd), c.lo), c.hi);
  if constexpr (P == PolicyType::kForget) {
    r = _mm_add_ps(_mm_mul_ps(c.a, v), select(occ, c.add_occ, c.add_emp));
  }
  if constexpr (P == PolicyType::kClampLower) r = _mm_max_ps(_mm_add_ps(v, odd), c.lo);
  if constexpr (P == PolicyType::kClampUpper) r = _mm_min_ps(_mm_add_ps(v, odd), c.hi);
  // storedValue(): within +-kMaxStoredFloat (maxps gives its second operand for a NaN).
  return _mm_min_ps(_mm_max_ps(r, _mm_sub_ps(_mm_setzero_ps(), c.bound)), c.bound);
}

/// new - old of four floats, added in double to `sum`.
inline __m128d addChanges(__m128d sum, __m128 now, __m128 was) {
  const __m128d d_lo = _mm_sub_pd(_mm_cvtps_pd(now), _mm_cvtps_pd(was));
  const __m128d d_hi =
      _mm_sub_pd(_mm_cvtps_pd(_mm_movehl_ps(now, now)), _mm_cvtps_pd(_mm_movehl_ps(was, was)));
  return _mm_add_pd(sum, _mm_add_pd(d_lo, d_hi));
}

}  // namespace tile_sse

/// Float tiles in SSE2: four cells an instruction; a row's unobserved cells keep their stored
/// values.
template <PolicyType P>
inline double updateTileCellsSse2(const ShiftedPolicy& sp, FloatTile* t, std::uint64_t e,
                                  std::uint64_t o) {
  using namespace tile_sse;
  const Consts c(sp);
  const std::uint64_t observed = e | o;
  __m128d sum = _mm_setzero_pd();
  for (unsigned row = 0; row < 64; row += 8) {
    const auto obs = static_cast<unsigned>(observed >> row) & 0xFFu;
    if (obs == 0) continue;
    const auto occ = static_cast<unsigned>(o >> row) & 0xFFu;
    for (unsigned k = 0; k < 8; k += 4) {
      const unsigned seen = (obs >> k) & 0xFu;
      if (seen == 0) continue;
      float* v = t->v + row + k;
      const __m128 was = _mm_loadu_ps(v);
      __m128 now = policy<P>(c, was, lanes(occ >> k));
      if (seen != 0xFu) now = select(lanes(seen), now, was);
      sum = addChanges(sum, now, was);
      _mm_storeu_ps(v, now);
    }
  }
  double parts[2];
  _mm_storeu_pd(parts, sum);
  return parts[0] + parts[1];
}

/// Float tiles: a row an instruction where the CPU runs AVX2 (tile_update_avx2.h), else four
/// cells one; the same result either way.
template <PolicyType P>
inline double updateTileCells(const ShiftedPolicy& sp, FloatTile* t, std::uint64_t e,
                              std::uint64_t o) {
#if defined(WAVOG_TILE_AVX2)
  if (tile_avx2::available()) return tile_avx2::update<P>(sp, t, e, o);
#endif
  return updateTileCellsSse2<P>(sp, t, e, o);
}
#endif

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_UPDATE_TILE_UPDATE_H_
