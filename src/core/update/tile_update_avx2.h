// The float tile update of tile_update.h eight cells an instruction, for CPUs with AVX2 (chosen
// at run time: the build stays x86-64's baseline). A row of a tile is one register. The result
// is the SSE2 path's, bit for bit: the same IEEE operations on every cell, and the changes added
// in double in the same order (test_tiles compares the two). Not installed; included only by
// src/core/update/tile_update.h.
#ifndef WAVOG_MAPPING_SRC_CORE_UPDATE_TILE_UPDATE_AVX2_H_
#define WAVOG_MAPPING_SRC_CORE_UPDATE_TILE_UPDATE_AVX2_H_

#include <cstdint>

#if defined(__x86_64__) && defined(__GNUC__)
#define WAVOG_TILE_AVX2 1
#include <immintrin.h>

#include "storage/tile.h"
#include "update/update_policy.h"

namespace wavog {
namespace detail {
namespace tile_avx2 {

/// True when this CPU runs AVX2 (asked once).
inline bool available() {
  static const bool yes = __builtin_cpu_supports("avx2") != 0;
  return yes;
}

/// updateTileCells() for a float tile: a row an instruction, with tile_sse::policy()'s steps on
/// eight cells. The changes of a row's cells c0..c7 go into the two-lane sum as (c0 + c2, c1 +
/// c3), then (c4 + c6, c5 + c7), as the SSE2 path adds its half rows (an unobserved cell's change
/// is +0, which adds nothing). One function without vector arguments or results: AVX2 code is
/// only ever entered through it.
template <PolicyType P>
[[gnu::target("avx2")]] double update(const ShiftedPolicy& sp, FloatTile* t, std::uint64_t e,
                                      std::uint64_t o) {
  const __m256 odd_occ = _mm256_set1_ps(static_cast<float>(sp.odd_occ));
  const __m256 odd_emp = _mm256_set1_ps(static_cast<float>(sp.odd_emp));
  const __m256 lo = _mm256_set1_ps(static_cast<float>(sp.lo));
  const __m256 hi = _mm256_set1_ps(static_cast<float>(sp.hi));
  const __m256 a = _mm256_set1_ps(static_cast<float>(sp.a));
  const __m256 add_occ = _mm256_set1_ps(static_cast<float>(sp.add_occ));
  const __m256 add_emp = _mm256_set1_ps(static_cast<float>(sp.add_emp));
  const __m256 bound = _mm256_set1_ps(kMaxStoredFloat);
  const __m256 minus_bound = _mm256_sub_ps(_mm256_setzero_ps(), bound);
  const __m256i bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
  const std::uint64_t observed = e | o;
  __m128d sum = _mm_setzero_pd();
  for (unsigned row = 0; row < 64; row += 8) {
    const auto obs = static_cast<int>((observed >> row) & 0xFFu);
    if (obs == 0) continue;
    const auto occ_bits = static_cast<int>((o >> row) & 0xFFu);
    // All-ones lanes for the row's O cells and for its observed ones.
    const __m256 occ = _mm256_castsi256_ps(
        _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(occ_bits), bit), bit));
    const __m256 seen =
        _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(obs), bit), bit));
    float* v = t->v + row;
    const __m256 was = _mm256_loadu_ps(v);
    const __m256 odd = _mm256_blendv_ps(odd_emp, odd_occ, occ);
    __m256 r = was;
    if constexpr (P == PolicyType::kNone) r = _mm256_add_ps(was, odd);
    if constexpr (P == PolicyType::kMax) r = _mm256_max_ps(was, odd);
    if constexpr (P == PolicyType::kClamp) {
      r = _mm256_min_ps(_mm256_max_ps(_mm256_add_ps(was, odd), lo), hi);
    }
    if constexpr (P == PolicyType::kForget) {
      r = _mm256_add_ps(_mm256_mul_ps(a, was), _mm256_blendv_ps(add_emp, add_occ, occ));
    }
    if constexpr (P == PolicyType::kClampLower) r = _mm256_max_ps(_mm256_add_ps(was, odd), lo);
    if constexpr (P == PolicyType::kClampUpper) r = _mm256_min_ps(_mm256_add_ps(was, odd), hi);
    r = _mm256_min_ps(_mm256_max_ps(r, minus_bound), bound);  // storedValue()
    const __m256 now = _mm256_blendv_ps(was, r, seen);
    const __m256d c03 = _mm256_sub_pd(_mm256_cvtps_pd(_mm256_castps256_ps128(now)),
                                      _mm256_cvtps_pd(_mm256_castps256_ps128(was)));
    const __m256d c47 = _mm256_sub_pd(_mm256_cvtps_pd(_mm256_extractf128_ps(now, 1)),
                                      _mm256_cvtps_pd(_mm256_extractf128_ps(was, 1)));
    sum = _mm_add_pd(sum, _mm_add_pd(_mm256_castpd256_pd128(c03), _mm256_extractf128_pd(c03, 1)));
    sum = _mm_add_pd(sum, _mm_add_pd(_mm256_castpd256_pd128(c47), _mm256_extractf128_pd(c47, 1)));
    _mm256_storeu_ps(v, now);
  }
  double parts[2];
  _mm_storeu_pd(parts, sum);
  return parts[0] + parts[1];
}

}  // namespace tile_avx2
}  // namespace detail
}  // namespace wavog

#endif  // __x86_64__ && __GNUC__
#endif  // WAVOG_MAPPING_SRC_CORE_UPDATE_TILE_UPDATE_AVX2_H_
