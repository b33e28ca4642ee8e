// The differential oracle of fuzz_integrate against the dense reference. Kept in its own file,
// compiled without libFuzzer's coverage instrumentation: its loops over every cell are checks,
// not code under test, and would otherwise dominate the run time.
#include "reference_oracle.h"

#include <algorithm>
#include <cmath>

#include "fuzz_support.h"

namespace wavog_fuzz {

using wavog::Aggregation;
using wavog::CellBox;
using wavog::Raster;
using wavog::WaveletMap;

constexpr double kTolerance = 1e-4;  // as test_reference_equivalence: |tree - ref| / max(1, |ref|)

namespace {
double relError(double got, double want) {
  return std::fabs(got - want) / std::max(1.0, std::fabs(want));
}
}  // namespace

void expectCellsEqual(const WaveletMap& map, const wavog_test::DenseReference& ref,
                      const Box* cleared, const char* when) {
  const CellBox& e = ref.extent();
  const double r = map.resolution();
  const double init = map.params().initValue();
  // The cells clearBox documents: centres in [min, max].
  const auto in_box = [&](std::int64_t x, std::int64_t y) {
    return cleared != nullptr && cleared->min_x <= cleared->max_x &&
           cleared->min_y <= cleared->max_y && x >= std::ceil(cleared->min_x / r - 0.5) &&
           x <= std::floor(cleared->max_x / r - 0.5) && y >= std::ceil(cleared->min_y / r - 0.5) &&
           y <= std::floor(cleared->max_y / r - 0.5);
  };
  // Every cell through the scale-0 read-out; the point queries on a sparse lattice of cells
  // (they walk the tree once per cell, the read-out once per window).
  const Raster r0 = map.exportScale(0, e, Aggregation::kMean);
  constexpr std::int64_t kQueryStride = 5;
  for (std::int64_t y = e.min_y; y < e.max_y; ++y) {
    for (std::int64_t x = e.min_x; x < e.max_x; ++x) {
      const bool gone = in_box(x, y);
      const double want = gone ? init : ref.value(x, y);
      const bool want_known = gone ? false : ref.known(x, y);
      const auto k = static_cast<std::size_t>((y - e.min_y) * e.width() + (x - e.min_x));
      const double got = r0.log_odds[k];
      WAVOG_FUZZ_CHECK(
          relError(got, want) <= kTolerance && (r0.known[k] != 0) == want_known,
          "%s: cell (%lld, %lld) read-out %.9g observed %d, reference %.9g observed %d", when,
          static_cast<long long>(x), static_cast<long long>(y), got, r0.known[k], want, want_known);
      if ((x + 3 * y) % kQueryStride != 0) continue;
      WAVOG_FUZZ_CHECK(
          relError(map.value({x, y}), want) <= kTolerance && map.isObserved({x, y}) == want_known,
          "%s: cell (%lld, %lld) value() %.9g observed %d, reference %.9g observed %d", when,
          static_cast<long long>(x), static_cast<long long>(y),
          static_cast<double>(map.value({x, y})), map.isObserved({x, y}), want, want_known);
    }
  }
}

void expectScalesEqual(const WaveletMap& map, const wavog_test::DenseReference& ref,
                       int max_scale) {
  const CellBox& e = ref.extent();
  const int top = std::min(max_scale, map.params().grid.block_levels);
  for (int s = 1; s <= top; ++s) {
    const CellBox box{-((-e.min_x) >> s), -((-e.min_y) >> s), e.max_x >> s, e.max_y >> s};
    const Raster mean = map.exportScale(s, box, Aggregation::kMean);
    const Raster mx = map.exportScale(s, box, Aggregation::kMax);
    const std::int64_t size = std::int64_t{1} << s;
    for (std::int64_t by = box.min_y; by < box.max_y; ++by) {
      for (std::int64_t bx = box.min_x; bx < box.max_x; ++bx) {
        const auto k = static_cast<std::size_t>((by - box.min_y) * box.width() + (bx - box.min_x));
        const double want_mean = ref.blockMean(s, bx, by);
        double scale_of_block = std::fabs(want_mean);
        for (std::int64_t y = by * size; y < (by + 1) * size; ++y)
          for (std::int64_t x = bx * size; x < (bx + 1) * size; ++x)
            scale_of_block = std::max(scale_of_block, std::fabs(ref.value(x, y)));
        const bool any = ref.blockAnyKnown(s, bx, by);
        WAVOG_FUZZ_CHECK(
            std::fabs(mean.log_odds[k] - want_mean) / std::max(1.0, scale_of_block) <= kTolerance &&
                (mean.known[k] != 0) == any && (mx.known[k] != 0) == any,
            "scale %d block (%lld, %lld): mean %.9g known %d, reference %.9g known %d", s,
            static_cast<long long>(bx), static_cast<long long>(by),
            static_cast<double>(mean.log_odds[k]), mean.known[k], want_mean, any);
        if (any) {
          const double want_max = ref.blockMaxObserved(s, bx, by);
          WAVOG_FUZZ_CHECK(relError(mx.log_odds[k], want_max) <= kTolerance,
                           "scale %d block (%lld, %lld): max %.9g, reference %.9g", s,
                           static_cast<long long>(bx), static_cast<long long>(by),
                           static_cast<double>(mx.log_odds[k]), want_max);
        }
      }
    }
  }
}

}  // namespace wavog_fuzz
