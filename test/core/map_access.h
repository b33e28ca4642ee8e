// Test-only window into WaveletMap's private storage (stored details, lazy counts).
#ifndef WAVOG_MAPPING_TEST_CORE_MAP_ACCESS_H_
#define WAVOG_MAPPING_TEST_CORE_MAP_ACCESS_H_

#include <functional>

#include "../../src/core/storage/map_impl.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog {

struct MapAccess {
  static WaveletMap::Impl& impl(WaveletMap& m) { return *m.impl_; }
  /// Calls f(node, level, pending count including ancestors) for every stored node.
  static void forEachNode(WaveletMap& m,
                          const std::function<void(const detail::Node&, int, int)>& f) {
    auto& im = *m.impl_;
    std::function<void(const detail::Node&, int, int)> rec = [&](const detail::Node& n, int l,
                                                                 int above) {
      f(n, l, above + n.k);
      if (l <= 1) return;
      for (int q = 0; q < 4; ++q) {
        if (im.hasChild(n, q)) rec(im.child(n, q), l - 1, above + n.k);
      }
    };
    for (auto& kv : im.blocks) {
      if (kv.second.has_root) rec(kv.second.root, im.levels, 0);
    }
  }
};

}  // namespace wavog

#endif  // WAVOG_MAPPING_TEST_CORE_MAP_ACCESS_H_
