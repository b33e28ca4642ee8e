// The storage of normal-distribution cells (MapParams::ndt): each block keeps the Gaussians of its
// finest cells as moments in a vector, most of it sorted by the cells' Morton codes within the
// block (so the cells under any quadtree node are one contiguous run), the latest new cells in an
// unsorted tail that is merged in when it grows. Moments are sums of weighted end-points in
// coordinates relative to the cell's centre, in double: a cell's covariance comes out without
// the cancellation of map-frame moments. Not installed; included only by src/core/*.
#ifndef WAVOG_MAPPING_SRC_CORE_NDT_STORE_H_
#define WAVOG_MAPPING_SRC_CORE_NDT_STORE_H_

#include <algorithm>
#include <cstdint>
#include <vector>

namespace wavog {
namespace detail {

/// The moments of one finest cell's end-points (weights w_i, offsets (x_i, y_i) from the centre).
struct NdtMoments {
  double w = 0.0;                      ///< sum w_i
  double sx = 0.0, sy = 0.0;           ///< sum w_i x_i, sum w_i y_i
  double sxx = 0.0, sxy = 0.0, syy = 0.0;  ///< sum w_i x_i^2, sum w_i x_i y_i, sum w_i y_i^2

  void scale(double f) {
    w *= f;
    sx *= f;
    sy *= f;
    sxx *= f;
    sxy *= f;
    syy *= f;
  }
  void add(double g, double x, double y) {
    w += g;
    sx += g * x;
    sy += g * y;
    sxx += g * x * x;
    sxy += g * x * y;
    syy += g * y * y;
  }
};

/// One finest cell holding a Gaussian: its Morton code within its block and its moments.
struct NdtEntry {
  std::uint32_t code = 0;
  NdtMoments m;
};

/// A block's Gaussians: entries [0, sorted) ascend by code, the rest is the unsorted tail.
struct NdtCells {
  std::vector<NdtEntry> entries;
  std::size_t sorted = 0;

  bool empty() const { return entries.empty(); }
  /// The entry of `code`, or nullptr.
  const NdtEntry* find(std::uint32_t code) const {
    return const_cast<NdtCells*>(this)->find(code);
  }
  NdtEntry* find(std::uint32_t code) {
    const auto end = entries.begin() + static_cast<std::ptrdiff_t>(sorted);
    const auto it = std::lower_bound(entries.begin(), end, code,
                                     [](const NdtEntry& e, std::uint32_t c) { return e.code < c; });
    if (it != end && it->code == code) return &*it;
    for (auto t = end; t != entries.end(); ++t) {
      if (t->code == code) return &*t;
    }
    return nullptr;
  }
  /// Sorts the tail into the sorted part when it is longer than kTail and an eighth of it, so
  /// that lookups stay cheap and a new cell costs amortised O(1) moves.
  void mergeTailIfLong() {
    const std::size_t tail = entries.size() - sorted;
    if (tail <= kTail || tail * 8 <= sorted) return;
    mergeTail();
  }
  void mergeTail() {
    const auto mid = entries.begin() + static_cast<std::ptrdiff_t>(sorted);
    const auto by_code = [](const NdtEntry& a, const NdtEntry& b) { return a.code < b.code; };
    std::sort(mid, entries.end(), by_code);
    std::inplace_merge(entries.begin(), mid, entries.end(), by_code);
    sorted = entries.size();
  }
  /// Removes the entries for which drop(entry) is true, keeping both parts' order.
  template <typename Drop>
  void removeIf(Drop drop) {
    std::size_t out = 0, sorted_out = 0;
    for (std::size_t i = 0; i < entries.size(); ++i) {
      if (drop(entries[i])) continue;
      if (i < sorted) ++sorted_out;
      entries[out++] = entries[i];
    }
    entries.resize(out);
    sorted = sorted_out;
    if (entries.capacity() > 4 * entries.size() + 16) entries.shrink_to_fit();
  }

  static constexpr std::size_t kTail = 32;
};

/// Morton code of the cell at (lx, ly) within its block: x in the even bits, y in the odd ones,
/// so that the cells of child q = (x bit) + 2 (y bit) of a node at level l share bits 2l and up
/// and have q in bits 2(l-1), 2(l-1)+1.
inline std::uint32_t mortonCode(std::uint32_t lx, std::uint32_t ly) {
  const auto spread = [](std::uint32_t v) {
    v &= 0xFFFFu;
    v = (v | (v << 8)) & 0x00FF00FFu;
    v = (v | (v << 4)) & 0x0F0F0F0Fu;
    v = (v | (v << 2)) & 0x33333333u;
    v = (v | (v << 1)) & 0x55555555u;
    return v;
  };
  return spread(lx) | (spread(ly) << 1);
}

/// The cell (lx, ly) of a Morton code.
inline void mortonCell(std::uint32_t code, std::uint32_t* lx, std::uint32_t* ly) {
  const auto compact = [](std::uint32_t v) {
    v &= 0x55555555u;
    v = (v | (v >> 1)) & 0x33333333u;
    v = (v | (v >> 2)) & 0x0F0F0F0Fu;
    v = (v | (v >> 4)) & 0x00FF00FFu;
    v = (v | (v >> 8)) & 0x0000FFFFu;
    return v;
  };
  *lx = compact(code);
  *ly = compact(code >> 1);
}

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_NDT_STORE_H_
