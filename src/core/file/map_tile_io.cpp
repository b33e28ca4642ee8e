// The dense leaf tiles of native map files (map_io.cpp, the layout there): a tile node's tile
// written and read (version 7, values as f64), and a tile-level node read as a Haar node (every
// older version) made a tile. Not installed; part of the core library.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <type_traits>

#include "file/map_codec.h"
#include "wavog_mapping/core/haar.h"
#include "wavog_mapping/core/limits.h"

namespace wavog {
namespace detail {

void writeTile(const WaveletMap::Impl& impl, const Node& n, Writer* w) {
  impl.withTile(n, [&](const auto& t) {
    w->put(t.known);
    w->put(t.base);
    for (std::uint64_t m = tileCells(impl.tile_level); m != 0; m &= m - 1) {
      w->put(static_cast<double>(t.v[__builtin_ctzll(m)]));
    }
  });
}

// Stores `cells` as the tile of node n (a fresh map's), float or wide as the map keeps them.
static void storeTile(WaveletMap::Impl& impl, Node& n, const WideTile& cells) {
  NodeStore store = impl.serialStore();
  impl.addTile(store, n);
  impl.withTile(n, [&](auto& t) {
    using T = std::remove_reference_t<decltype(t.v[0])>;
    for (std::size_t i = 0; i < 64; ++i) t.v[i] = storedValue<T>(cells.v[i]);
    t.known = cells.known;
    t.base = cells.base;
  });
}

// Reads the tile of node n (a fresh map's; its flags read and checked).
void readTile(WaveletMap::Impl& impl, Node& n, Reader* r) {
  WideTile t;
  fillTile(&t, impl.tile_level, false);
  const std::uint64_t cells = tileCells(impl.tile_level);
  t.known = r->get<std::uint64_t>();
  t.base = r->get<double>();
  if ((t.known & ~cells) != 0) throw std::runtime_error("bad tile cells");
  if (!std::isfinite(t.base) || std::fabs(t.base) > kMaxStoredLogOdds) {
    throw std::runtime_error("bad tile base");
  }
  for (std::uint64_t m = cells; m != 0; m &= m - 1) {
    const auto v = r->get<double>();
    // A cell's value is its node's average plus v - base, each within the bound.
    if (!std::isfinite(v) || std::fabs(v) > kMaxStoredLogOdds) {
      throw std::runtime_error(beyondBound("a tile cell", v));
    }
    t.v[__builtin_ctzll(m)] = v;
  }
  const TileKnowledge k = tileKnowledge(impl.tile_level, t.known);
  if (k.all != n.known_all || k.any != n.known_any) {
    throw std::runtime_error("a tile's cells disagree with its node's knowledge");
  }
  for (double d : n.d) {
    if (d != 0.0) throw std::runtime_error("a tile node with details");
  }
  storeTile(impl, n, t);
}

// The cells below node n (level l, first cell (x0, y0) of its tile, average avg, pending
// multiplier of its details mult) into tile t, with their knowledge.
static void tileCellsOf(const WaveletMap::Impl& impl, const Node& n, int l, unsigned x0,
                        unsigned y0, double avg, double mult, WideTile* t) {
  const double d[3] = {n.d[0] * mult, n.d[1] * mult, n.d[2] * mult};
  const auto c = haar::backward(avg, d);
  const unsigned half = 1u << (l - 1);
  for (int q = 0; q < 4; ++q) {
    const unsigned x = x0 + ((q & 1) ? half : 0), y = y0 + ((q & 2) ? half : 0);
    const double cq = c[static_cast<std::size_t>(q)];
    if (l > 1 && impl.hasChild(n, q)) {
      const Node& ch = impl.child(n, q);
      tileCellsOf(impl, ch, l - 1, x, y, cq, mult * impl.multiplier(ch.k), t);
      continue;
    }
    const std::uint64_t cells = tileSquare(l - 1, x, y);
    for (std::uint64_t m = cells; m != 0; m &= m - 1) {
      t->v[__builtin_ctzll(m)] = cq;
    }
    if ((n.known_all >> q) & 1u) t->known |= cells;
  }
}

// A node of the tile level read as a Haar node (every file before version 7; a version-7 file
// may hold one too): n and its subtree become a tile node,
// its cells at base 0 (their value minus the node's average); n keeps its pending count.
void makeTile(WaveletMap::Impl& impl, Node& n) {
  WideTile cells;
  fillTile(&cells, impl.tile_level, false);
  tileCellsOf(impl, n, impl.tile_level, 0, 0, 0.0, 1.0, &cells);
  NodeStore store = impl.serialStore();
  impl.freeSubtree(store, n);
  n.d[0] = n.d[1] = n.d[2] = 0.0;
  storeTile(impl, n, cells);
}

}  // namespace detail
}  // namespace wavog
