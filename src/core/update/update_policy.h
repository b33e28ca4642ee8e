// The update policies of one cell (paper section 1.3) as compile-time choices: the value after an
// E or O observation, and which policies update a uniform block exactly at its own scale.
// Not installed; included only by src/core/*.
#ifndef WAVOG_MAPPING_SRC_CORE_UPDATE_UPDATE_POLICY_H_
#define WAVOG_MAPPING_SRC_CORE_UPDATE_UPDATE_POLICY_H_

#include <algorithm>
#include <cstdint>

#include "wavog_mapping/core/params.h"
#include "wavog_mapping/core/types.h"

namespace wavog {
namespace detail {

/// Policy constants for one scan: odd values, forgetting a = 1 - g and g, clamp bounds, the
/// tolerance below which an E update counts as changing nothing (ALGORITHM.md section 3.4), and
/// the pending units standing for a in a lazy tag (WaveletMap::Impl::multiplier(units) == a).
struct PolicyConsts {
  double odd_occ, odd_emp, a, g, lo, hi, unchanged_tol;
  std::uint64_t units;
};

/// The value of a cell at log-odds x after an E (cls kEmpty) or O observation.
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

/// applyPolicy() for values held shifted by `shift` (a tile's stored values, storage/tile.h): the
/// constants moved once per tile instead of every value twice.
struct ShiftedPolicy {
  double odd_occ, odd_emp;     ///< the added odd values (max: the compared ones, shifted)
  double lo, hi;               ///< the clamp bounds, shifted
  double a, add_occ, add_emp;  ///< forget: a v + add
};
template <PolicyType P>
inline ShiftedPolicy shiftPolicy(const PolicyConsts& pc, double shift) {
  ShiftedPolicy s;
  const double odd_shift = P == PolicyType::kMax ? shift : 0.0;
  s.odd_occ = pc.odd_occ + odd_shift;
  s.odd_emp = pc.odd_emp + odd_shift;
  s.lo = pc.lo + shift;
  s.hi = pc.hi + shift;
  s.a = pc.a;
  s.add_occ = pc.g * pc.odd_occ + (1.0 - pc.a) * shift;
  s.add_emp = pc.g * pc.odd_emp + (1.0 - pc.a) * shift;
  return s;
}
template <PolicyType P>
inline double applyShifted(const ShiftedPolicy& sp, CellClass cls, double v) {
  const bool occ = cls == CellClass::kOccupied;
  const double o = occ ? sp.odd_occ : sp.odd_emp;
  if constexpr (P == PolicyType::kNone) return v + o;
  if constexpr (P == PolicyType::kMax) return std::max(v, o);
  if constexpr (P == PolicyType::kClamp) return std::min(std::max(v + o, sp.lo), sp.hi);
  if constexpr (P == PolicyType::kForget) return sp.a * v + (occ ? sp.add_occ : sp.add_emp);
  if constexpr (P == PolicyType::kClampLower) return std::max(v + o, sp.lo);
  if constexpr (P == PolicyType::kClampUpper) return std::min(v + o, sp.hi);
  return v;
}

/// The E update is affine on every cell (so exact on a block average, details untouched or
/// scaled): none, forget, and clamp_upper (x + odd_emp < x <= hi never reaches the bound).
template <PolicyType P>
constexpr bool kAffineEmpty =
    P == PolicyType::kNone || P == PolicyType::kForget || P == PolicyType::kClampUpper;

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_UPDATE_UPDATE_POLICY_H_
