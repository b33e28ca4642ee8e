// The log-odds of many finest cells of one block (the reflection map's sweeps of faded hits,
// reflection_update.h): each read descends from the deepest node it shares with the cell read
// before it, not from the root as WaveletMap::Impl::read does, so cells read in Morton code order
// cost only the levels in which they differ. Not installed; included only by src/core/*.
#ifndef WAVOG_MAPPING_SRC_CORE_STORAGE_CELL_READER_H_
#define WAVOG_MAPPING_SRC_CORE_STORAGE_CELL_READER_H_

#include <algorithm>
#include <array>
#include <cstdint>

#include "storage/map_impl.h"
#include "wavog_mapping/core/haar.h"

namespace wavog {
namespace detail {

/// Reads the finest cells of block `b` by their Morton codes within it (any order; cheapest in
/// ascending order), with the values of WaveletMap::Impl::read(0, x, y). The block must not change
/// while the reader is in use.
class BlockCellReader {
 public:
  BlockCellReader(const WaveletMap::Impl& impl, const Block& b)
      : impl_(impl), levels_(impl.levels), uniform_(!b.has_root), s_(b.s) {
    if (!uniform_) path_[levels_] = {&b.root, b.s, impl.multiplier(b.root.k)};
    reached_ = levels_;
  }

  /// The log-odds (average) of the finest cell of `code`.
  double average(std::uint32_t code) {
    if (uniform_) return s_;
    // The nodes above level l hold both this cell and the last one when their codes agree in
    // the bits from 2 l up; the path is known down to level reached_.
    int l = reached_;
    const std::uint32_t differ = code ^ last_;
    if (differ != 0) l = std::max(l, (31 - __builtin_clz(differ)) / 2 + 1);
    last_ = code;
    for (;; --l) {
      const Step& st = path_[l];
      if (WaveletMap::Impl::hasTile(*st.n)) {
        reached_ = l;
        return impl_.withTile(*st.n, [&](const auto& t) {
          return st.avg + st.mult * (t.v[kTileMorton.cell[code & 63u]] - t.base);
        });
      }
      const int q = static_cast<int>((code >> (2 * (l - 1))) & 3u);
      const double d[3] = {st.n->d[0] * st.mult, st.n->d[1] * st.mult, st.n->d[2] * st.mult};
      const double avg = haar::backwardChild(st.avg, d, q);
      if (l == 1 || !impl_.hasChild(*st.n, q)) {
        reached_ = l;
        return avg;
      }
      const Node& c = impl_.child(*st.n, q);
      path_[l - 1] = {&c, avg, st.mult * impl_.multiplier(c.k)};
    }
  }

 private:
  // A node on the path to the last cell read, its average, and the factor of its stored details
  // (the product of its own and its ancestors' pending multipliers).
  struct Step {
    const Node* n = nullptr;
    double avg = 0.0;
    double mult = 1.0;
  };

  const WaveletMap::Impl& impl_;
  const int levels_;
  const bool uniform_;  // the block has no nodes: every cell reads s_
  const double s_;
  std::array<Step, 13> path_{};  // path_[l]: the level-l node (block_levels <= 12)
  int reached_ = 0;              // the last read stopped at the level-reached_ node
  std::uint32_t last_ = 0;       // the last code read
};

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_STORAGE_CELL_READER_H_
