// The block updates with the hits of the reflection map (MapParams::reflection), one per policy
// (and "forget" with the Gaussians too), compiled apart from integrate.cpp so that the walks
// without them are compiled as they are.
#include "update/block_update.h"

namespace wavog {
namespace detail {

#define WAVOG_UPDATE_BLOCKS(P, NDT, HITS)                                                          \
  template std::uint64_t updateBlocks<P, NDT, HITS>(                                               \
      WaveletMap::Impl&, NodeStore&, const ScanClassifier&, const PolicyConsts&, const NdtConsts*, \
      const HitConsts*, const std::vector<BlockJob>&, std::atomic<std::size_t>*);
WAVOG_UPDATE_BLOCKS(PolicyType::kNone, false, true)
WAVOG_UPDATE_BLOCKS(PolicyType::kMax, false, true)
WAVOG_UPDATE_BLOCKS(PolicyType::kClamp, false, true)
WAVOG_UPDATE_BLOCKS(PolicyType::kForget, false, true)
WAVOG_UPDATE_BLOCKS(PolicyType::kClampLower, false, true)
WAVOG_UPDATE_BLOCKS(PolicyType::kClampUpper, false, true)
WAVOG_UPDATE_BLOCKS(PolicyType::kForget, true, true)
#undef WAVOG_UPDATE_BLOCKS

}  // namespace detail
}  // namespace wavog
