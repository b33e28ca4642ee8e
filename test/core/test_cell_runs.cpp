// The sparse store of the payload cells (src/core/storage/cell_runs.h) and the reflection map's
// bits of the cells that hold an entry (src/core/payloads/reflection_store.h), against a std::map
// of the same cells:
// random batches of updates and new cells as a scan brings them (clustered codes), drops, removals
// and merges keep every entry once, both runs ascending, and the bits set exactly where an entry
// is; the gallops find what std::lower_bound / std::upper_bound find.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <random>
#include <vector>

#include "../../src/core/storage/cell_runs.h"
#include "../../src/core/payloads/reflection_store.h"

namespace wavog_test {
namespace {

using wavog::detail::CellBits;
using wavog::detail::CellRuns;
using wavog::detail::gallop;
using wavog::detail::gallopBack;
using wavog::detail::HitCount;

constexpr int kLevels = 5;  // 1024 cells
constexpr std::uint32_t kCells = 1u << (2 * kLevels);

struct Item {
  std::uint32_t code;
};

// Both runs ascending, every code once, and exactly the live counts of `want`.
void expectSame(const CellRuns<HitCount>& runs,
                const std::map<std::uint32_t, std::uint32_t>& want) {
  const auto by_code = [](const HitCount& a, const HitCount& b) { return a.code < b.code; };
  ASSERT_LE(runs.sorted, runs.entries.size());
  EXPECT_TRUE(std::is_sorted(runs.entries.begin(), runs.entries.begin() + runs.sorted, by_code));
  EXPECT_TRUE(std::is_sorted(runs.entries.begin() + runs.sorted, runs.entries.end(), by_code));
  std::map<std::uint32_t, std::uint32_t> live;
  std::size_t dead = 0;
  for (const HitCount& e : runs.entries) {
    if (e.live()) {
      EXPECT_TRUE(live.emplace(e.code, e.n).second) << "cell " << e.code << " twice";
    } else {
      ++dead;
    }
  }
  EXPECT_EQ(dead, runs.dead);
  EXPECT_EQ(live, want);
}

// One scan's upsertSorted() of `items` as the reflection map makes it: the bits rebuilt when out
// of step, set for each new entry (a count of 1), asked before each search; update(e) on the
// entries found. Returns the cells searched.
template <typename Update>
std::size_t upsertWithBits(CellRuns<HitCount>* runs, CellBits* bits, const std::vector<Item>& items,
                           Update update) {
  if (!bits->inStep(*runs)) bits->rebuild(*runs, kLevels);
  std::size_t searched = 0;
  runs->upsertSorted(
      items.data(), items.data() + items.size(), [&](HitCount& e, const Item&) { update(e); },
      [bits](const Item& it) {
        bits->set(it.code);
        HitCount e;
        e.code = it.code;
        e.n = 1;
        return e;
      },
      [&](std::uint32_t code) {
        const bool may = bits->test(code);
        searched += may ? 1 : 0;
        return may;
      });
  bits->step(*runs);
  return searched;
}

TEST(CellRuns, GallopsFindTheBounds) {
  std::mt19937 rng(7);
  for (int round = 0; round < 200; ++round) {
    std::vector<HitCount> v(rng() % 40);
    for (HitCount& e : v) e.code = rng() % 64;
    std::sort(v.begin(), v.end(),
              [](const HitCount& a, const HitCount& b) { return a.code < b.code; });
    HitCount* b = v.data();
    HitCount* e = v.data() + v.size();
    for (std::uint32_t c = 0; c < 66; ++c) {
      const auto lower =
          std::lower_bound(b, e, c, [](const HitCount& x, std::uint32_t k) { return x.code < k; });
      const auto upper =
          std::upper_bound(b, e, c, [](std::uint32_t k, const HitCount& x) { return k < x.code; });
      EXPECT_EQ(gallop(b, e, c), lower) << "code " << c;
      EXPECT_EQ(gallopBack(b, e, c), upper) << "code " << c;
    }
  }
}

TEST(CellRuns, ScansOfUpdatesAndNewCellsDropsAndMerges) {
  std::mt19937 rng(11);
  CellRuns<HitCount> runs;
  CellBits bits;
  std::map<std::uint32_t, std::uint32_t> want;
  std::size_t searched = 0, skipped = 0;
  for (int scan = 0; scan < 400; ++scan) {
    // A scan's cells: a few clusters of neighbouring codes, ascending, each once.
    std::vector<std::uint32_t> codes;
    const int clusters = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < clusters; ++k) {
      const std::uint32_t at = rng() % kCells, len = 1 + rng() % 24;
      for (std::uint32_t c = at; c < std::min(kCells, at + len); ++c) {
        if (rng() % 3 != 0) codes.push_back(c);
      }
    }
    std::sort(codes.begin(), codes.end());
    codes.erase(std::unique(codes.begin(), codes.end()), codes.end());
    std::vector<Item> items;
    for (std::uint32_t c : codes) items.push_back({c});

    const std::size_t found =
        upsertWithBits(&runs, &bits, items, [](HitCount& e) { e.n = e.live() ? e.n + 1 : 1; });
    searched += found;
    skipped += items.size() - found;
    for (std::uint32_t c : codes) ++want[c];
    if (scan % 3 == 0) {
      runs.mergeTailIfLong();
    } else if (scan % 7 == 0) {
      runs.mergeTail();
      EXPECT_EQ(runs.sorted, runs.entries.size());
    }
    // Drops (as sweeps and the walk make them) and, now and then, removal of the dead entries.
    for (HitCount& e : runs.entries) {
      if (e.live() && rng() % 10 == 0) {
        want.erase(e.code);
        runs.drop(&e);
      }
    }
    if (scan % 5 == 0) runs.removeDeadIfMany();
    if (scan % 50 == 0) {
      runs.removeIf([](const HitCount& e) { return e.code % 5 == 0; });
      for (auto it = want.begin(); it != want.end();)
        it = it->first % 5 == 0 ? want.erase(it) : std::next(it);
    }
    expectSame(runs, want);
    if (::testing::Test::HasFailure()) return;
  }
  // A dead entry revived by upsertSorted counts from 1 again: the map above says so too. Both
  // kinds of cells occurred: those the bits let skip the search and those searched.
  EXPECT_GT(skipped, 1000u);
  EXPECT_GT(searched, 1000u);
}

TEST(CellBits, SetExactlyWhereAnEntryIsAfterEveryChange) {
  std::mt19937 rng(3);
  CellRuns<HitCount> runs;
  CellBits bits;
  for (int round = 0; round < 60; ++round) {
    std::vector<Item> items;
    for (std::uint32_t c = rng() % 64; c < kCells; c += 1 + rng() % 97) items.push_back({c});
    upsertWithBits(&runs, &bits, items, [](HitCount& e) { e.n = 1; });
    runs.mergeTailIfLong();
    if (round % 4 == 3) runs.removeIf([&rng](const HitCount&) { return rng() % 3 == 0; });
    // Out of step after entries were removed; rebuilt, exact.
    if (!bits.inStep(runs)) bits.rebuild(runs, kLevels);
    std::vector<bool> has(kCells, false);
    for (const HitCount& e : runs.entries) has[e.code] = true;
    for (std::uint32_t c = 0; c < kCells; ++c) ASSERT_EQ(bits.test(c), has[c]) << "cell " << c;
  }
  // The bits follow one runs at a time: another run of the same size is not in step.
  CellRuns<HitCount> other;
  other.entries = runs.entries;
  EXPECT_FALSE(bits.inStep(other));
}

}  // namespace
}  // namespace wavog_test
