// The storage of normal-distribution cells (MapParams::ndt): each block keeps the Gaussians of its
// finest cells as moments in a vector, most of it sorted by the cells' Morton codes within the
// block (so the cells under any quadtree node are one contiguous run of each of its two sorted
// runs), the latest new cells in a short second run that is merged in when it grows. Moments are
// sums of weighted end-points in coordinates relative to the cell's centre, in double: a cell's
// covariance comes out without the cancellation of map-frame moments. Not installed; included only
// by src/core/*.
#ifndef WAVOG_MAPPING_SRC_CORE_NDT_STORE_H_
#define WAVOG_MAPPING_SRC_CORE_NDT_STORE_H_

#include <algorithm>
#include <cstdint>
#include <vector>

namespace wavog {
namespace detail {

/// The moments of one finest cell's end-points (weights w_i, offsets (x_i, y_i) from the centre).
struct NdtMoments {
  double w = 0.0;                          ///< sum w_i
  double sx = 0.0, sy = 0.0;               ///< sum w_i x_i, sum w_i y_i
  double sxx = 0.0, sxy = 0.0, syy = 0.0;  ///< sum w_i x_i^2, sum w_i x_i y_i, sum w_i y_i^2

  void scale(double f) {
    w *= f;
    sx *= f;
    sy *= f;
    sxx *= f;
    sxy *= f;
    syy *= f;
  }
  /// Adds the moments `m` of a cell whose centre lies at (ox, oy) from this one's origin (the
  /// parallel-axis shift).
  void addShifted(const NdtMoments& m, double ox, double oy) {
    w += m.w;
    sx += m.sx + m.w * ox;
    sy += m.sy + m.w * oy;
    sxx += m.sxx + 2.0 * ox * m.sx + m.w * ox * ox;
    sxy += m.sxy + ox * m.sy + oy * m.sx + m.w * ox * oy;
    syy += m.syy + 2.0 * oy * m.sy + m.w * oy * oy;
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

/// A block's Gaussians: two runs ascending by code, entries [0, sorted) and the short tail after
/// them that takes new cells (merged into the first run when it outgrows twice the square root of
/// it, so a new cell costs amortised O(sqrt(n)) moves). A dropped Gaussian stays as an entry of
/// weight 0 (live() is false) until dead ones are a quarter of the entries.
struct NdtCells {
  std::vector<NdtEntry> entries;
  std::size_t sorted = 0;
  std::size_t dead = 0;

  static bool live(const NdtEntry& e) { return e.m.w > 0.0; }
  bool empty() const { return entries.size() == dead; }
  /// The entry of `code` (live or dead), or nullptr.
  const NdtEntry* find(std::uint32_t code) const { return const_cast<NdtCells*>(this)->find(code); }
  NdtEntry* find(std::uint32_t code) {
    NdtEntry* e = findIn(entries.data(), entries.data() + sorted, code);
    return e != nullptr ? e
                        : findIn(entries.data() + sorted, entries.data() + entries.size(), code);
  }
  /// The entry of `code`, made empty in the tail if there is none.
  NdtEntry& findOrInsert(std::uint32_t code) {
    NdtEntry* e = find(code);
    if (e != nullptr) return *e;
    const auto pos =
        std::upper_bound(entries.begin() + static_cast<std::ptrdiff_t>(sorted), entries.end(), code,
                         [](std::uint32_t c, const NdtEntry& x) { return c < x.code; });
    ++dead;  // empty until its first end-point is added
    if (entries.size() == entries.capacity()) {
      // Grow by a quarter (not the usual double): at most 25 % of the bytes go unused.
      const auto at = pos - entries.begin();
      entries.reserve(entries.size() + entries.size() / 4 + kTail);
      return *entries.insert(entries.begin() + at, NdtEntry{code, {}});
    }
    return *entries.insert(pos, NdtEntry{code, {}});
  }
  /// Merges the tail into the first run when it is longer than 2 sqrt(sorted) and kTail.
  void mergeTailIfLong() {
    const std::size_t tail = entries.size() - sorted;
    if (tail <= kTail || tail * tail <= 4 * sorted) return;
    const auto by_code = [](const NdtEntry& a, const NdtEntry& b) { return a.code < b.code; };
    std::inplace_merge(entries.begin(), entries.begin() + static_cast<std::ptrdiff_t>(sorted),
                       entries.end(), by_code);
    sorted = entries.size();
  }
  /// Drops the Gaussian of `e` (a live entry).
  void drop(NdtEntry* e) {
    e->m = NdtMoments{};
    ++dead;
  }
  /// Removes the dead entries when they are a quarter of all.
  void removeDeadIfMany() {
    if (dead * 4 > entries.size() + kTail) removeIf([](const NdtEntry& e) { return !live(e); });
  }
  /// Removes the entries for which drop(entry) is true, keeping both runs' order.
  template <typename Drop>
  void removeIf(Drop drop) {
    std::size_t out = 0, sorted_out = 0;
    dead = 0;
    for (std::size_t i = 0; i < entries.size(); ++i) {
      if (drop(entries[i])) continue;
      if (i < sorted) ++sorted_out;
      dead += live(entries[i]) ? 0 : 1;
      entries[out++] = entries[i];
    }
    entries.resize(out);
    sorted = sorted_out;
    if (entries.capacity() > 4 * entries.size() + 16) entries.shrink_to_fit();
  }

  static constexpr std::size_t kTail = 32;

 private:
  static NdtEntry* findIn(NdtEntry* b, NdtEntry* e, std::uint32_t code) {
    NdtEntry* it =
        std::lower_bound(b, e, code, [](const NdtEntry& x, std::uint32_t c) { return x.code < c; });
    return it != e && it->code == code ? it : nullptr;
  }
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
