// Dense leaf tiles: the finest cells below a node of the tile level (3: 8 x 8 cells; the root of a
// block of 2 levels: 4 x 4) stored as floats, not as a subtree, wherever they are not uniform.
// A cell's value is the node's Haar average plus f (v - base), f the node's pending forgetting
// multiplier (its own and its ancestors' tags): the tree above the tile is the Haar tree as
// elsewhere, and the tile holds what lies below its node's average. An update rewrites only the
// cells it observes and moves base with the node's average, so a cell the scans do not reach keeps
// its stored float (no drift from its neighbours' updates, issue 37). Part of WaveletMap's private
// storage; not installed, included only by src/core/* and the core tests.
#ifndef WAVOG_MAPPING_SRC_CORE_STORAGE_TILE_H_
#define WAVOG_MAPPING_SRC_CORE_STORAGE_TILE_H_

#include <array>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "wavog_mapping/core/limits.h"

namespace wavog {
namespace detail {

/// The finest cells of a tile node: cell (x, y) of the tile at index x + 8 y, stored as T.
/// Float under the policies that bound every value (clamp, forget, max): there an update's
/// round-off does not add up (a clamped value is exact, forgetting contracts the error). Double
/// under the unbounded ones (none, clamp_lower, clamp_upper), whose values grow with every scan
/// that sees the cell: in float, 100,000 repetitions of one fan (test_repeated_scan) drift by
/// 1e-3 of the value, over the reference tolerance.
template <typename T>
struct TileOf {
  T v[64];              ///< stored values (see the file comment)
  std::uint64_t known;  ///< bit x + 8 y: the cell was observed
  double base;          ///< the stored value of a cell at its node's average
};
using FloatTile = TileOf<float>;
using WideTile = TileOf<double>;
static_assert(std::is_trivial<FloatTile>::value && std::is_trivial<WideTile>::value,
              "tiles must stay trivial (uncleared pool chunks)");
static_assert(sizeof(FloatTile) == 272 && sizeof(WideTile) == 528, "Tile layout grew");

/// The largest float within kMaxStoredLogOdds (limits.h): a float rounds 1e30 up.
constexpr float kMaxStoredFloat = 9.99999939e29f;
static_assert(kMaxStoredFloat <= kMaxStoredLogOdds &&
                  kMaxStoredFloat * (1.0 + 1.0 / (1 << 23)) > kMaxStoredLogOdds,
              "kMaxStoredFloat is the float below the bound");

/// v as a tile stores it: within the bound of a map file (keepStored(), map_slot.h; for a float,
/// kMaxStoredFloat), rounded to T, so that every file a map saves loads. x > lo ? x : lo and
/// x < hi ? x : hi are one maxsd and one minsd (NaN goes to the lower bound).
template <typename T>
inline T storedValue(double v) {
  constexpr double kMax =
      std::is_same<T, float>::value ? static_cast<double>(kMaxStoredFloat) : kMaxStoredLogOdds;
  const double up = v > -kMax ? v : -kMax;
  return static_cast<T>(up < kMax ? up : kMax);
}

/// Node::child_mask bit of a tile node: Node::children is the index of its Tile.
constexpr std::uint8_t kTileBit = 0x10;

/// The level of a block's tile nodes: 3, or the root of a block of 2 levels.
constexpr int tileLevel(int block_levels) { return block_levels < 3 ? block_levels : 3; }

/// The cells of a tile of level t (bit x + 8 y): all 64, or the 4 x 4 of a level-2 tile.
constexpr std::uint64_t tileCells(int t) { return t >= 3 ? ~std::uint64_t{0} : 0x0F0F0F0Full; }

/// The cells of quadrant q (x offset h (q & 1), y offset h (q >> 1), h half the side) of a tile
/// of level t.
constexpr std::uint64_t tileQuadrant(int t, int q) {
  const int h = 1 << (t - 1);
  const std::uint64_t row = (std::uint64_t{1} << h) - 1;
  std::uint64_t m = 0;
  for (int y = 0; y < h; ++y) m |= row << (8 * y);
  return m << ((q & 1) * h + (q >> 1) * 8 * h);
}

/// The masks above as a table (they are asked for on every tile update and read).
struct TileShapes {
  std::uint64_t quadrant[2][4]{};  ///< [t - 2][q]: tileQuadrant(t, q)
  std::uint64_t square[4]{};       ///< [s]: the square of side 2^s at (0, 0)
  constexpr TileShapes() {
    for (int t = 2; t <= 3; ++t) {
      for (int q = 0; q < 4; ++q) quadrant[t - 2][q] = tileQuadrant(t, q);
    }
    for (int s = 0; s <= 3; ++s) square[s] = tileQuadrant(s + 1, 0);
  }
};
inline constexpr TileShapes kTileShapes{};

/// The cells of the square of side 2^s whose first cell is (x, y) of the tile (bit x + 8 y).
inline std::uint64_t tileSquare(int s, unsigned x, unsigned y) {
  return kTileShapes.square[s] << (x + 8 * y);
}

/// The cells of mask m, without a library call (the baseline build has no popcnt instruction).
inline unsigned cellCount(std::uint64_t m) {
  m -= (m >> 1) & 0x5555555555555555ull;
  m = (m & 0x3333333333333333ull) + ((m >> 2) & 0x3333333333333333ull);
  m = (m + (m >> 4)) & 0x0F0F0F0F0F0F0F0Full;
  return static_cast<unsigned>((m * 0x0101010101010101ull) >> 56);
}

/// The mean stored value of the cells of `cells` (not empty).
template <typename Tile>
inline double tileMean(const Tile& tile, std::uint64_t cells) {
  double sum = 0.0;
  for (std::uint64_t m = cells; m != 0; m &= m - 1) sum += tile.v[__builtin_ctzll(m)];
  return sum / static_cast<double>(cellCount(cells));
}

/// Morton code (x bits even, y bits odd) of tile cell index x + 8 y, and back.
struct TileMorton {
  std::array<std::uint8_t, 64> code{}, cell{};
  constexpr TileMorton() {
    for (unsigned i = 0; i < 64; ++i) {
      const unsigned x = i & 7u, y = i >> 3;
      unsigned c = 0;
      for (unsigned b = 0; b < 3; ++b)
        c |= ((x >> b) & 1u) << (2 * b) | ((y >> b) & 1u) << (2 * b + 1);
      code[i] = static_cast<std::uint8_t>(c);
      cell[c] = static_cast<std::uint8_t>(i);
    }
  }
};
inline constexpr TileMorton kTileMorton{};

/// The four knowledge bits of a tile node (bit q: quadrant q) from its cells' mask.
struct TileKnowledge {
  unsigned all, any;
};
inline TileKnowledge tileKnowledge(int t, std::uint64_t known) {
  TileKnowledge k{0, 0};
  for (int q = 0; q < 4; ++q) {
    const std::uint64_t m = kTileShapes.quadrant[t - 2][q];
    k.all |= static_cast<unsigned>((known & m) == m) << q;
    k.any |= static_cast<unsigned>((known & m) != 0) << q;
  }
  return k;
}

/// True when every cell of a tile of level t lies within tol of the node's average (f = 1) and
/// the cells are all observed or none: the tile carries nothing beyond its node's summary.
template <typename Tile>
inline bool tileUniform(const Tile& tile, int t, double tol) {
  const std::uint64_t cells = tileCells(t);
  const std::uint64_t k = tile.known & cells;
  if (k != 0 && k != cells) return false;
  const double lo = tile.base - tol, hi = tile.base + tol;
  for (std::uint64_t m = cells; m != 0; m &= m - 1) {
    const double v = tile.v[__builtin_ctzll(m)];
    if (!(v >= lo && v <= hi)) return false;
  }
  return true;
}

/// A tile of level t uniform at its node's average, observed entirely or not at all.
template <typename Tile>
inline void fillTile(Tile* tile, int t, bool known) {
  for (auto& v : tile->v) v = 0;
  tile->base = 0.0;
  tile->known = known ? tileCells(t) : 0;
}

/// Applies a pending multiplier m to the stored values (the node's tag, flushed).
template <typename Tile>
inline void scaleTile(Tile* tile, double m) {
  using T = std::remove_reference_t<decltype(tile->v[0])>;
  const double b = tile->base;
  for (T& v : tile->v) v = storedValue<T>(b + m * (static_cast<double>(v) - b));
}

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_STORAGE_TILE_H_
