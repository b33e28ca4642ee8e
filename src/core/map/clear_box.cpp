// Region clearing of WaveletMap: clearBox() sets every finest cell of a rectangle back to the
// prior and unobserved, block by block and coarse to fine, pruning what becomes trivial; its
// normal-distribution cells (MapParams::ndt) and hits (MapParams::reflection) go too.
#include <algorithm>
#include <array>
#include <cmath>
#include <type_traits>
#include <vector>

#include "update/map_slot.h"
#include "wavog_mapping/core/haar.h"
#include "wavog_mapping/core/limits.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog {

using detail::Block;
using detail::Node;

namespace {

struct ClearBox {
  std::int64_t x0, y0, x1, y1;  // inclusive finest-cell bounds
};

// clearNode() of a tile node (tag flushed; a uniform one is given a tile first).
double clearTile(WaveletMap::Impl& impl, detail::NodeStore& store, Node& n, std::int64_t ix0,
                 std::int64_t iy0, double s, const ClearBox& box) {
  if (!impl.hasTile(n)) impl.addTile(store, n);
  const std::int64_t side = std::int64_t{1} << impl.tile_level;
  const std::int64_t x0 = std::max(box.x0, ix0) - ix0, x1 = std::min(box.x1, ix0 + side - 1) - ix0;
  const std::int64_t y0 = std::max(box.y0, iy0) - iy0, y1 = std::min(box.y1, iy0 + side - 1) - iy0;
  const double ds = impl.withTile(n, [&](auto& t) {
    using T = std::remove_reference_t<decltype(t.v[0])>;
    const double offset = t.base - s;  // stored value of a cell minus its value
    double sum = 0.0;
    for (std::int64_t y = y0; y <= y1; ++y) {
      for (std::int64_t x = x0; x <= x1; ++x) {
        T& v = t.v[x + 8 * y];
        const T now = detail::storedValue<T>(impl.init + offset);
        sum += static_cast<double>(now) - static_cast<double>(v);
        v = now;
        t.known &= ~(std::uint64_t{1} << (x + 8 * y));
      }
    }
    const double change = sum / static_cast<double>(side * side);
    t.base = detail::keepStored(t.base + change);
    return change;
  });
  impl.dropTileIfUniform(store, n);
  return ds;
}

// Sets every finest cell of the box inside node `n` (level l, origin ix0/iy0, average s) back to
// the prior and unobserved. Returns the change of n's average.
double clearNode(WaveletMap::Impl& impl, detail::NodeStore& store, Node& n, int l, std::int64_t ix0,
                 std::int64_t iy0, double s, const ClearBox& box) {
  impl.flush(n);
  if (l == impl.tile_level) return clearTile(impl, store, n, ix0, iy0, s, box);
  const auto c = haar::backward(s, n.d);
  std::array<double, 4> delta{};
  const std::int64_t half = std::int64_t{1} << (l - 1);
  for (int q = 0; q < 4; ++q) {
    const std::int64_t cx = ix0 + ((q & 1) ? half : 0);
    const std::int64_t cy = iy0 + ((q & 2) ? half : 0);
    const std::int64_t ex = cx + half - 1, ey = cy + half - 1;
    if (ex < box.x0 || cx > box.x1 || ey < box.y0 || cy > box.y1) continue;
    detail::ChildSlot slot(impl, store, n, q);
    const double cq = c[static_cast<std::size_t>(q)];
    const bool inside = cx >= box.x0 && ex <= box.x1 && cy >= box.y0 && ey <= box.y1;
    if (inside || l == 1) {
      if (l > 1 && impl.hasChild(n, q)) slot.remove();
      delta[static_cast<std::size_t>(q)] = impl.init - cq;
      slot.setKnown(false, false);
      continue;
    }
    delta[static_cast<std::size_t>(q)] = detail::refineSlot(slot, slot.node(), [&](Node& m) {
      return clearNode(impl, store, m, l - 1, cx, cy, cq, box);
    });
  }
  return detail::foldChanges(n, delta);
}

}  // namespace

std::size_t WaveletMap::clearBox(double min_x, double min_y, double max_x, double max_y) {
  if (!(min_x <= max_x && min_y <= max_y)) return 0;  // also rejects NaN
  Impl& impl = *impl_;
  for (WaveletMap* layer : {impl.hits_layer.get(), impl.misses_layer.get()}) {
    if (layer != nullptr) layer->clearBox(min_x, min_y, max_x, max_y);
  }
  const double r = impl.params.grid.resolution;
  // Cells whose centre (i + 0.5) r lies in [min, max], clamped to one cell beyond the extent on
  // each side (no block lies there), so any bounds, +-inf included, convert exactly.
  const ClearBox box{
      clampedCellIndex(std::ceil(min_x / r - 0.5)), clampedCellIndex(std::ceil(min_y / r - 0.5)),
      clampedCellIndex(std::floor(max_x / r - 0.5)), clampedCellIndex(std::floor(max_y / r - 0.5))};
  if (box.x1 < box.x0 || box.y1 < box.y0) return 0;
  const int L = impl.levels;
  const std::int64_t size = std::int64_t{1} << L;
  std::vector<std::uint64_t> keys;
  for (const auto& kv : impl.blocks) {
    const std::int64_t bx = detail::blockKeyX(kv.first), by = detail::blockKeyY(kv.first);
    const std::int64_t x0 = bx * size, y0 = by * size;
    if (x0 + size - 1 < box.x0 || x0 > box.x1 || y0 + size - 1 < box.y0 || y0 > box.y1) continue;
    keys.push_back(kv.first);
  }
  for (std::uint64_t key : keys) {
    Block& b = impl.blocks.at(key);
    const std::int64_t bx = detail::blockKeyX(key), by = detail::blockKeyY(key);
    const std::int64_t x0 = bx * size, y0 = by * size;
    const bool inside =
        x0 >= box.x0 && x0 + size - 1 <= box.x1 && y0 >= box.y0 && y0 + size - 1 <= box.y1;
    if (inside) {
      if (b.has_root) impl.removeRoot(&b);
      impl.eraseBlock(key);
      continue;
    }
    const auto in_box = [&](const auto& e) {
      std::uint32_t lx, ly;
      detail::mortonCell(e.code, &lx, &ly);
      const std::int64_t ix = x0 + lx, iy = y0 + ly;
      return ix >= box.x0 && ix <= box.x1 && iy >= box.y0 && iy <= box.y1;
    };
    if (b.ndt) b.ndt->removeIf(in_box);
    if (b.hits) {
      b.hits->counts.removeIf(in_box);
      b.hits->ratios.removeIf(in_box);
      b.hits->pairs.removeIf(in_box);
    }
    // The block's groups stay with it (as in an integration, see NodeStore).
    detail::NodeStore store(impl.pool, impl.tiles, &b.spare, &impl.counts);
    detail::RootSlot slot(impl, store, b);
    const double s = b.s;
    const double ds = detail::refineSlot(
        slot, slot.node(), [&](Node& m) { return clearNode(impl, store, m, L, x0, y0, s, box); });
    b.s = detail::keepStored(b.s + ds);
    impl.dropIfEmpty(bx, by);
  }
  return keys.size();
}

}  // namespace wavog
