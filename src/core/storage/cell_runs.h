// The sparse payload store of a block's finest cells (MapParams::ndt, MapParams::reflection):
// entries sorted by the cells' Morton codes within the block, so that the cells under any quadtree
// node are one contiguous run. Not installed; included only by src/core/*.
#ifndef WAVOG_MAPPING_SRC_CORE_STORAGE_CELL_RUNS_H_
#define WAVOG_MAPPING_SRC_CORE_STORAGE_CELL_RUNS_H_

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace wavog {
namespace detail {

/// The first entry of [b, e) (ascending by code) whose code is not below `code`: steps of 1, 2,
/// 4, ... from b, then a binary search in the last one (cheap when it is near b).
template <typename Entry>
Entry* gallop(Entry* b, Entry* e, std::uint32_t code) {
  std::size_t step = 1;
  Entry* lo = b;
  while (lo != e && lo->code < code) {
    const auto left = static_cast<std::size_t>(e - lo);
    Entry* hi = lo + std::min(step, left);
    if (hi == e || hi->code >= code) {
      return std::lower_bound(lo, hi, code,
                              [](const Entry& x, std::uint32_t c) { return x.code < c; });
    }
    lo = hi;
    step *= 2;
  }
  return lo;
}

/// The first entry of [b, e) (ascending by code) from which on every code is above `code`
/// (std::upper_bound), searched from e back: steps of 1, 2, 4, ..., then a binary search.
template <typename Entry>
Entry* gallopBack(Entry* b, Entry* e, std::uint32_t code) {
  std::size_t step = 1;
  Entry* hi = e;  // [hi, e) are above `code`
  while (hi != b) {
    Entry* lo = hi - std::min(step, static_cast<std::size_t>(hi - b));
    if (lo->code <= code) {
      return std::upper_bound(lo, hi, code,
                              [](std::uint32_t c, const Entry& x) { return c < x.code; });
    }
    hi = lo;
    step *= 2;
  }
  return b;
}

/// The entries of one block's finest cells that hold a payload (Entry: a u32 `code`, `live()`,
/// `kill()`; a value-initialised Entry is dead): two runs ascending by code, entries [0, sorted)
/// and the short tail after them that takes new cells (merged into the first run when it outgrows
/// twice the square root of it, or of sorted k for batches of k, so a new cell costs amortised
/// O(sqrt(n)) moves). A dropped entry stays, dead, until dead ones are a quarter of the entries.
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
    const auto at = pos - entries.begin();
    reserveFor(1);
    return *entries.insert(entries.begin() + at, fresh);
  }
  /// For items [first, last) ascending by `code` (one per cell): update(entry, item) on the entry
  /// of each item's cell, live or dead (it must leave it live), or, when it has none, a new
  /// entry make(item) (live); new entries join the tail as one sorted batch. Cells for which
  /// may_have(code) is false have no entry (they are not searched).
  template <typename Item, typename Update, typename Make, typename MayHave>
  void upsertSorted(const Item* first, const Item* last, Update update, Make make,
                    MayHave may_have) {
    const std::size_t old_size = entries.size();
    const auto items = static_cast<std::size_t>(last - first);
    reserveFor(items);  // room for every item: no pointer below moves
    Entry* const run_end = entries.data() + sorted;
    Entry* const tail_end = entries.data() + old_size;
    // The items ascend: each search goes on from where the last one ended, in both runs; new
    // entries go after the tail, ascending too.
    Entry* in_run = entries.data();
    Entry* in_tail = run_end;
    for (const Item* it = first; it != last; ++it) {
      if (!may_have(it->code)) {
        entries.push_back(make(*it));
        continue;
      }
      in_run = gallop(in_run, run_end, it->code);
      Entry* e = in_run != run_end && in_run->code == it->code ? in_run : nullptr;
      if (e == nullptr) {
        in_tail = gallop(in_tail, tail_end, it->code);
        if (in_tail != tail_end && in_tail->code == it->code) e = in_tail;
      }
      if (e == nullptr) {
        entries.push_back(make(*it));
        continue;
      }
      if (!e->live()) --dead;
      update(*e, *it);
    }
    mergeAdded(old_size);
  }
  /// For items [first, last) ascending by `code`, none of whose cells has an entry (live or
  /// dead): new entries make(item), joining the tail as one sorted batch.
  template <typename Item, typename Make>
  void insertNewSorted(const Item* first, const Item* last, Make make) {
    const std::size_t old_size = entries.size();
    reserveFor(static_cast<std::size_t>(last - first));
    for (const Item* it = first; it != last; ++it) entries.push_back(make(*it));
    mergeAdded(old_size);
  }
  /// Merges the entries from `old_size` on (new, ascending) into the tail.
  void mergeAdded(std::size_t old_size) {
    added_ = entries.size() - old_size;
    mergeBack(sorted, old_size);
  }
  /// Merges the tail into the first run when it is longer than kTail and 2 sqrt(sorted k), k the
  /// entries the last upsertSorted() added (1 for single inserts): with k new entries at a time,
  /// that balances the merges' moves (sorted k / tail) against the tail's (tail).
  void mergeTailIfLong() {
    const std::size_t tail = entries.size() - sorted;
    const std::size_t k = std::max<std::size_t>(1, added_);
    added_ = 0;
    if (tail <= kTail || tail * tail <= 4 * sorted * k) return;
    mergeTail();
  }
  /// Merges the tail into the first run.
  void mergeTail() {
    added_ = 0;
    mergeBack(0, sorted);
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
  // Room for `extra` more entries, growing by a quarter (not the usual double) when there is none:
  // at most 25 % of the bytes (and the last request's room) go unused.
  void reserveFor(std::size_t extra) {
    const std::size_t n = entries.size();
    if (n + extra > entries.capacity()) entries.reserve(n + extra + n / 4 + kTail);
  }

  std::size_t added_ = 0;  // entries the last upsertSorted() added

  // Merges the entries [mid, end), ascending, into [begin, mid), ascending, from the back: the
  // entries of [begin, mid) move once, in blocks (found by gallopBack(): what a scan adds comes in
  // clusters), through a buffer kept from call to call for those of [mid, end).
  void mergeBack(std::size_t begin, std::size_t mid) {
    if (mid == entries.size()) return;
    thread_local std::vector<Entry> moving;
    moving.assign(entries.begin() + static_cast<std::ptrdiff_t>(mid), entries.end());
    Entry* out = entries.data() + entries.size();
    Entry* t = entries.data() + mid;  // one past the entries of [begin, mid) not yet moved
    Entry* const t_begin = entries.data() + begin;
    for (std::size_t a = moving.size(); a > 0; --a) {
      Entry* const above = gallopBack(t_begin, t, moving[a - 1].code);
      out = std::move_backward(above, t, out);
      t = above;
      *--out = moving[a - 1];
    }
  }

  // The entry of `code` in [b, e), or nullptr; `at`: where it is or would be.
  static Entry* findIn(Entry* b, Entry* e, std::uint32_t code, Entry** at = nullptr) {
    Entry* it =
        std::lower_bound(b, e, code, [](const Entry& x, std::uint32_t c) { return x.code < c; });
    if (at != nullptr) *at = it;
    return it != e && it->code == code ? it : nullptr;
  }
};

/// The entries of a block's two sorted runs (CellRuns) under one square: [b1, e1) and [b2, e2).
template <typename Entry>
struct CellSpan {
  Entry *b1 = nullptr, *e1 = nullptr, *b2 = nullptr, *e2 = nullptr;
  /// Runs at most this long are split by one linear pass, longer ones by binary searches.
  static constexpr std::ptrdiff_t kLinearSplit = 16;

  bool empty() const { return b1 == e1 && b2 == e2; }
  /// The entries under child q of the level-l square (their codes' bits 2(l-1), 2(l-1)+1 are q).
  void split(int l, CellSpan out[4]) const {
    splitRun(b1, e1, l, &out[0].b1, &out[0].e1, &out[1].b1, &out[1].e1, &out[2].b1, &out[2].e1,
             &out[3].b1, &out[3].e1);
    splitRun(b2, e2, l, &out[0].b2, &out[0].e2, &out[1].b2, &out[1].e2, &out[2].b2, &out[2].e2,
             &out[3].b2, &out[3].e2);
  }
  template <typename F>
  void forEach(F f) const {
    for (Entry* x = b1; x != e1; ++x) f(x);
    for (Entry* x = b2; x != e2; ++x) f(x);
  }

 private:
  static void splitRun(Entry* b, Entry* e, int l, Entry** b0, Entry** e0, Entry** b1, Entry** e1,
                       Entry** b2, Entry** e2, Entry** b3, Entry** e3) {
    const int shift = 2 * (l - 1);
    Entry *m0, *m1, *m2;
    if (e - b <= kLinearSplit) {
      // Short runs (most, near the finest cells): count each child's entries in one pass without
      // a branch on the codes (they are sorted, so the counts place the cuts).
      std::ptrdiff_t n0 = 0, n1 = 0, n2 = 0;
      for (const Entry* x = b; x != e; ++x) {
        const unsigned q = (x->code >> shift) & 3u;
        n0 += q == 0;
        n1 += q <= 1;
        n2 += q <= 2;
      }
      m0 = b + n0;
      m1 = b + n1;
      m2 = b + n2;
    } else {
      const auto upto = [shift](unsigned q) {
        return [shift, q](const Entry& x) { return ((x.code >> shift) & 3u) <= q; };
      };
      m0 = std::partition_point(b, e, upto(0));
      m1 = m0 == e ? e : std::partition_point(m0, e, upto(1));
      m2 = m1 == e ? e : std::partition_point(m1, e, upto(2));
    }
    *b0 = b;
    *e0 = *b1 = m0;
    *e1 = *b2 = m1;
    *e2 = *b3 = m2;
    *e3 = e;
  }
};

/// Every entry of `runs` (no entry may be added or moved while the span is in use).
template <typename Entry>
CellSpan<Entry> spanOf(CellRuns<Entry>* runs) {
  Entry* base = runs->entries.data();
  CellSpan<Entry> sp;
  sp.b1 = base;
  sp.e1 = sp.b2 = base + runs->sorted;
  sp.e2 = base + runs->entries.size();
  return sp;
}

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

#endif  // WAVOG_MAPPING_SRC_CORE_STORAGE_CELL_RUNS_H_
