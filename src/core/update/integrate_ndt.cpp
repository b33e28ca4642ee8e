// The block update of "forget" with normal-distribution cells (MapParams::ndt): the quadtree walk
// that also forgets the Gaussians the scan observes, compiled apart from integrate.cpp so that the
// other policies' walks are compiled as they are without it.
#include "update/block_update.h"

namespace wavog {
namespace detail {

template std::uint64_t updateBlocks<PolicyType::kForget, true, false>(
    WaveletMap::Impl&, NodeStore&, const ScanClassifier&, const PolicyConsts&, const NdtConsts*,
    const HitConsts*, const std::vector<BlockJob>&, std::atomic<std::size_t>*);

}  // namespace detail
}  // namespace wavog
