// WaveletMap::integrate: one scan into the map (ALGORITHM.md sections 3 and 6). The scan is
// prepared and classified by the ScanClassifier (scan_classifier.h); every block within its
// reach that is not U goes through the quadtree update Integrator<P> (quadtree_update.h), one
// instantiation per update policy.
#include <algorithm>
#include <cmath>

#include "map_impl.h"
#include "quadtree_update.h"
#include "scan_classifier.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog {
namespace {

using detail::ScanClassifier;

// Numerical floor of the "E update changes nothing" test (log-odds).
constexpr double kUnchangedFloor = 1e-9;

// Box of finest cells [min, max) holding every cell within `reach` (m) of (px, py). prepare()
// refuses a scan whose pose plus reach leaves the extent (limits.h), so the casts are exact.
CellBox reachBox(double px, double py, double reach, double res) {
  CellBox box;
  box.min_x = static_cast<std::int64_t>(std::floor((px - reach) / res));
  box.min_y = static_cast<std::int64_t>(std::floor((py - reach) / res));
  box.max_x = static_cast<std::int64_t>(std::floor((px + reach) / res)) + 1;
  box.max_y = static_cast<std::int64_t>(std::floor((py + reach) / res)) + 1;
  return box;
}

template <PolicyType P>
std::uint64_t integrateAll(WaveletMap::Impl& impl, const ScanClassifier& cls, IntegrateStats* st) {
  const MapParams& p = impl.params;
  const detail::PolicyConsts pc{p.sensor.odd_occ,
                                p.sensor.odd_emp,
                                impl.a,
                                P == PolicyType::kForget ? p.policy.gamma : 0.0,
                                p.policy.clamp_min,
                                p.policy.clamp_max,
                                std::max(p.skip_tolerance, kUnchangedFloor)};
  detail::Integrator<P> integrator(impl, cls, pc);
  const detail::PreparedScan& ps = cls.scan();
  const int L = impl.levels;
  const double block_size = static_cast<double>(std::int64_t{1} << L) * ps.res;
  const CellBox blocks = reachBox(ps.px, ps.py, ps.reach, block_size);
  std::uint64_t visited = 0;
  for (std::int64_t by = blocks.min_y; by < blocks.max_y; ++by) {
    for (std::int64_t bx = blocks.min_x; bx < blocks.max_x; ++bx) {
      const std::int64_t ix0 = detail::scaleUp(bx, L), iy0 = detail::scaleUp(by, L);
      const detail::SquareInfo box = cls.classifySquare(L, ix0, iy0);
      ++visited;
      if (box.cls == CellClass::kUnknown) continue;
      ++st->blocks_touched;
      integrator.integrateBlock(impl.getOrCreateBlock(bx, by), ix0, iy0, box);
    }
  }
  return visited + integrator.visited();
}

// One instantiation per policy, in the order of PolicyType's enumerators.
using IntegrateFn = std::uint64_t (*)(WaveletMap::Impl&, const ScanClassifier&, IntegrateStats*);
constexpr IntegrateFn kIntegrateFor[] = {
    &integrateAll<PolicyType::kNone>,       &integrateAll<PolicyType::kMax>,
    &integrateAll<PolicyType::kClamp>,      &integrateAll<PolicyType::kForget>,
    &integrateAll<PolicyType::kClampLower>, &integrateAll<PolicyType::kClampUpper>};
static_assert(static_cast<int>(PolicyType::kNone) == 0 &&
                  static_cast<int>(PolicyType::kClampUpper) == 5,
              "kIntegrateFor follows PolicyType's order");

}  // namespace

IntegrateStats WaveletMap::integrate(const Pose2& sensor_pose, const ScanView& scan) {
  IntegrateStats st;
  // Per-thread scratch: its buffers are reused from scan to scan (see the header's
  // thread-safety note).
  thread_local ScanClassifier classifier;
  st.status = classifier.prepare(impl_->params, sensor_pose, scan, &st);
  if (st.status != ScanStatus::kOk) {
    classifier.releaseIfLarge();
    impl_->nodes_visited_last = 0;
    return st;
  }
  const detail::PreparedScan& ps = classifier.scan();
  st.touched = reachBox(ps.px, ps.py, ps.reach, ps.res);
  const auto policy = static_cast<std::size_t>(impl_->params.policy.type);
  st.nodes_visited = kIntegrateFor[policy](*impl_, classifier, &st);
  classifier.releaseIfLarge();
  impl_->nodes_visited_last = st.nodes_visited;
  return st;
}

}  // namespace wavog
