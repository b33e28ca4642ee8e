// The per-scan pseudo-bearing table of sector_table.h.
#include "classify/sector_table.h"

#include <algorithm>

namespace wavog {
namespace detail {
namespace {
constexpr double kTwoPi = 6.28318530717958647692;
}  // namespace

void SectorTable::prepare(int n, double amin, double inc) {
  if (n == n_ && amin == amin_ && inc == inc_) return;
  build(n, amin, inc);
  n_ = n;
  amin_ = amin;
  inc_ = inc;
}

void SectorTable::build(int n, double amin, double inc) {
  // Buckets of at most 1/16 of a beam step of pseudo-bearing (its slope is at least 1/2): most
  // cells find an exact sector, about one in 10-20 is near a boundary. At most 2^14 (64 KiB).
  std::size_t count = 64;
  while (count < (std::size_t{1} << 14) && static_cast<double>(count) * inc < 64.0) count *= 2;
  mask_ = static_cast<std::uint32_t>(count - 1);
  scale_ = static_cast<double>(count) / 4.0;
  if (n < 1 || !(inc <= kMaxStep)) {
    sector_.assign(count, kUnsure);
    return;
  }
  sector_.assign(count, n);  // outside the fan, until a sector or a boundary claims the bucket
  const auto buckets = static_cast<std::int64_t>(count);
  // Fills buckets [lo, hi] (any integers, hi - lo < buckets), cyclically.
  const auto fill = [&](std::int64_t lo, std::int64_t hi, std::int32_t value) {
    if (hi < lo) return;
    const std::int64_t first = ((lo % buckets) + buckets) % buckets;
    const std::int64_t len = hi - lo + 1;
    const std::int64_t head = std::min(len, buckets - first);
    std::fill_n(sector_.begin() + first, head, value);
    std::fill_n(sector_.begin(), len - head, value);
  };
  // The boundaries' pseudo-bearings, unwrapped counter-clockwise from boundary 0 (a step of
  // under kMaxStep rad never moves a pseudo-bearing back by 2 but across +x). Two sines and
  // cosines per boundary, once per geometry.
  const auto unwrapped = [&](int k, double prev) {
    const double b = amin + (static_cast<double>(k) - 0.5) * inc;
    double u = pseudoBearing(std::cos(b), std::sin(b));
    while (u < prev - 2.0) u += 4.0;
    return std::max(u, prev);
  };
  const double u0 = unwrapped(0, -1e300);
  double lo = u0;
  for (int j = 0; j < n; ++j) {  // sector j: buckets wholly within (u_j + M, u_j+1 - M)
    const double hi = unwrapped(j + 1, lo);
    fill(static_cast<std::int64_t>(std::ceil((lo + kPseudoMargin) * scale_)),
         static_cast<std::int64_t>(std::floor((hi - kPseudoMargin) * scale_)) - 1, j);
    lo = hi;
  }
  // Buckets within the margin of a boundary, last (they override the sectors' runs).
  const auto unsure = [&](double a, double b) {
    fill(static_cast<std::int64_t>(std::floor((a - kPseudoMargin) * scale_)),
         static_cast<std::int64_t>(std::floor((b + kPseudoMargin) * scale_)), kUnsure);
  };
  double u = u0;
  for (int k = 0; k <= n; ++k) {
    u = unwrapped(k, k == 0 ? -1e300 : u);
    unsure(u, u);
  }
  // A fan of (nearly) a whole turn: between its last boundary and its first (the seam lies there)
  // the reference's normalisation, not the wedges, decides.
  if (static_cast<double>(n) * inc >= kTwoPi - 1e-6) {
    unsure(std::min(u0, u - 4.0), std::max(u0, u - 4.0));
  }
}

}  // namespace detail
}  // namespace wavog
