// The sparse payload store of a block's finest cells (MapParams::ndt, MapParams::reflection):
// entries sorted by the cells' Morton codes within the block, so that the cells under any quadtree
// node are one contiguous run. Not installed; included only by src/core/*.
#ifndef WAVOG_MAPPING_SRC_CORE_CELL_RUNS_H_
#define WAVOG_MAPPING_SRC_CORE_CELL_RUNS_H_

#include <algorithm>
#include <cstdint>
#include <vector>

namespace wavog {
namespace detail {

/// The entries of one block's finest cells that hold a payload (Entry: a u32 `code`, `live()`,
/// `kill()`; a value-initialised Entry is dead): two runs ascending by code, entries [0, sorted) and the short
/// tail after them that takes new cells (merged into the first run when it outgrows twice the
/// square root of it, so a new cell costs amortised O(sqrt(n)) moves). A dropped entry stays, dead,
/// until dead ones are a quarter of the entries.
template <typename Entry>
struct CellRuns {
  std::vector<Entry> entries;
  std::size_t sorted = 0;
  std::size_t dead = 0;

  static bool live(const Entry& e) { return e.live(); }
  bool empty() const { return entries.size() == dead; }
  /// The entry of `code` (live or dead), or nullptr.
  const Entry* find(std::uint32_t code) const { return const_cast<CellRuns*>(this)->find(code); }
  Entry* find(std::uint32_t code) {
    Entry* e = findIn(entries.data(), entries.data() + sorted, code);
    return e != nullptr ? e
                        : findIn(entries.data() + sorted, entries.data() + entries.size(), code);
  }
  /// The entry of `code`, made empty in the tail if there is none.
  Entry& findOrInsert(std::uint32_t code) {
    Entry* e = find(code);
    if (e != nullptr) return *e;
    const auto pos =
        std::upper_bound(entries.begin() + static_cast<std::ptrdiff_t>(sorted), entries.end(), code,
                         [](std::uint32_t c, const Entry& x) { return c < x.code; });
    ++dead;  // empty until its first payload is added
    Entry fresh{};
    fresh.code = code;
    if (entries.size() == entries.capacity()) {
      // Grow by a quarter (not the usual double): at most 25 % of the bytes go unused.
      const auto at = pos - entries.begin();
      entries.reserve(entries.size() + entries.size() / 4 + kTail);
      return *entries.insert(entries.begin() + at, fresh);
    }
    return *entries.insert(pos, fresh);
  }
  /// Merges the tail into the first run when it is longer than 2 sqrt(sorted) and kTail.
  void mergeTailIfLong() {
    const std::size_t tail = entries.size() - sorted;
    if (tail <= kTail || tail * tail <= 4 * sorted) return;
    const auto by_code = [](const Entry& a, const Entry& b) { return a.code < b.code; };
    std::inplace_merge(entries.begin(), entries.begin() + static_cast<std::ptrdiff_t>(sorted),
                       entries.end(), by_code);
    sorted = entries.size();
  }
  /// Drops the payload of `e` (a live entry).
  void drop(Entry* e) {
    e->kill();
    ++dead;
  }
  /// Removes the dead entries when they are a quarter of all.
  void removeDeadIfMany() {
    if (dead * 4 > entries.size() + kTail) removeIf([](const Entry& e) { return !live(e); });
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
  static Entry* findIn(Entry* b, Entry* e, std::uint32_t code) {
    Entry* it =
        std::lower_bound(b, e, code, [](const Entry& x, std::uint32_t c) { return x.code < c; });
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

#endif  // WAVOG_MAPPING_SRC_CORE_CELL_RUNS_H_
