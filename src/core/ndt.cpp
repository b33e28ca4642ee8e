// Read-out of the normal-distribution cells (MapParams::ndt, paper section 1.2.3): the Gaussians
// of one window at scale s, each merging the moments of the finest cells under it exactly (the
// parallel-axis shift of each cell's moments to the coarse cell's centre, in double), and the
// Gaussian of one finest cell. Storage: ndt_store.h; update: ndt_update.h.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "map_impl.h"
#include "wavog_mapping/core/haar.h"
#include "wavog_mapping/core/limits.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog {

using detail::Block;
using detail::NdtEntry;
using detail::NdtMoments;
using detail::Node;

namespace {

void requireNdt(const WaveletMap::Impl& impl) {
  if (!impl.params.ndt) {
    throw std::logic_error("this map keeps no normal-distribution cells (MapParams::ndt)");
  }
}

// Moments about a common origin, accumulated from cells at offsets (ox, oy) from it.
struct MomentSum {
  double w = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
  void add(const NdtMoments& m, double ox, double oy) {
    w += m.w;
    sx += m.sx + m.w * ox;
    sy += m.sy + m.w * oy;
    sxx += m.sxx + 2.0 * ox * m.sx + m.w * ox * ox;
    sxy += m.sxy + ox * m.sy + oy * m.sx + m.w * ox * oy;
    syy += m.syy + 2.0 * oy * m.sy + m.w * oy * oy;
  }
};

// The Gaussian of moments `m` about the point (cx, cy) of the map frame.
NdtCell gaussian(const MomentSum& m, double cx, double cy) {
  NdtCell c;
  c.weight = m.w;
  const double mx = m.sx / m.w, my = m.sy / m.w;
  c.mean_x = cx + mx;
  c.mean_y = cy + my;
  c.cov_xx = std::max(0.0, m.sxx / m.w - mx * mx);
  c.cov_yy = std::max(0.0, m.syy / m.w - my * my);
  c.cov_xy = m.sxy / m.w - mx * my;
  return c;
}

// The Haar average of the scale-s cell (x, y) (lazy tags applied on the way, nothing written).
double averageAt(const WaveletMap::Impl& impl, int s, std::int64_t x, std::int64_t y) {
  const int L = impl.levels;
  const std::int64_t fx = detail::scaleUp(x, s), fy = detail::scaleUp(y, s);
  const Block* b = impl.findBlock(detail::floorShift(fx, L), detail::floorShift(fy, L));
  if (b == nullptr) return impl.init;
  double avg = b->s;
  if (!b->has_root) return b->known_any ? avg : impl.init;
  const Node* n = &b->root;
  double mult = 1.0;
  for (int l = L; l > s; --l) {
    mult *= impl.multiplier(n->k);
    const int q = static_cast<int>(((fx >> (l - 1)) & 1) | (((fy >> (l - 1)) & 1) << 1));
    const double d[3] = {n->d[0] * mult, n->d[1] * mult, n->d[2] * mult};
    avg = haar::backwardChild(avg, d, q);
    if (l - 1 == s || l == 1 || !impl.hasChild(*n, q)) return avg;
    n = &impl.child(*n, q);
  }
  return avg;
}

}  // namespace

NdtLayer WaveletMap::exportNdt(int scale, const CellBox& window) const {
  const Impl& impl = *impl_;
  requireNdt(impl);
  const int L = impl.levels;
  if (scale < 0 || scale > L) {
    throw std::invalid_argument("exportNdt: scale " + std::to_string(scale) + " outside [0, " +
                                std::to_string(L) + "]");
  }
  const double r = impl.params.grid.resolution;
  NdtLayer out;
  out.scale = scale;
  out.cell_size = r * std::ldexp(1.0, scale);
  out.box = window;
  if (window.empty()) return out;
  // Every finest cell in the window, with its scale-s cell.
  struct Item {
    std::int64_t cx, cy, ix, iy;
    const NdtMoments* m;
  };
  std::vector<Item> items;
  const std::int64_t span = std::int64_t{1} << (L - scale);  // scale-s cells per block side
  for (const auto& kv : impl.blocks) {
    const Block& b = kv.second;
    if (!b.ndt || b.ndt->empty()) continue;
    const std::int64_t bx = detail::blockKeyX(kv.first), by = detail::blockKeyY(kv.first);
    const std::int64_t x0 = bx * span, y0 = by * span;
    if (x0 + span <= window.min_x || x0 >= window.max_x || y0 + span <= window.min_y ||
        y0 >= window.max_y) {
      continue;
    }
    for (const NdtEntry& e : b.ndt->entries) {
      std::uint32_t lx, ly;
      detail::mortonCell(e.code, &lx, &ly);
      const std::int64_t ix = detail::scaleUp(bx, L) + lx, iy = detail::scaleUp(by, L) + ly;
      const std::int64_t cx = ix >> scale, cy = iy >> scale;
      if (cx < window.min_x || cx >= window.max_x || cy < window.min_y || cy >= window.max_y) {
        continue;
      }
      items.push_back({cx, cy, ix, iy, &e.m});
    }
  }
  std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
    if (a.cy != b.cy) return a.cy < b.cy;
    if (a.cx != b.cx) return a.cx < b.cx;
    if (a.iy != b.iy) return a.iy < b.iy;
    return a.ix < b.ix;
  });
  const double big = out.cell_size;
  for (std::size_t i = 0; i < items.size();) {
    const std::int64_t cx = items[i].cx, cy = items[i].cy;
    // Moments about the scale-s cell's centre.
    const double ccx = (static_cast<double>(cx) + 0.5) * big;
    const double ccy = (static_cast<double>(cy) + 0.5) * big;
    MomentSum sum;
    for (; i < items.size() && items[i].cx == cx && items[i].cy == cy; ++i) {
      const double ox = (static_cast<double>(items[i].ix) + 0.5) * r - ccx;
      const double oy = (static_cast<double>(items[i].iy) + 0.5) * r - ccy;
      sum.add(*items[i].m, ox, oy);
    }
    NdtCell c = gaussian(sum, ccx, ccy);
    c.ix = cx;
    c.iy = cy;
    c.log_odds = static_cast<float>(averageAt(impl, scale, cx, cy));
    out.cells.push_back(c);
  }
  return out;
}

bool WaveletMap::ndtCell(const CellIndex& cell, NdtCell* out) const {
  const Impl& impl = *impl_;
  requireNdt(impl);
  if (!inExtent(cell.x, cell.y)) return false;
  const int L = impl.levels;
  const Block* b = impl.findBlock(detail::floorShift(cell.x, L), detail::floorShift(cell.y, L));
  if (b == nullptr || !b->ndt) return false;
  const std::int64_t mask = (std::int64_t{1} << L) - 1;
  const NdtEntry* e = b->ndt->find(detail::mortonCode(static_cast<std::uint32_t>(cell.x & mask),
                                                      static_cast<std::uint32_t>(cell.y & mask)));
  if (e == nullptr) return false;
  const double r = impl.params.grid.resolution;
  MomentSum sum;
  sum.add(e->m, 0.0, 0.0);
  *out = gaussian(sum, (static_cast<double>(cell.x) + 0.5) * r,
                  (static_cast<double>(cell.y) + 0.5) * r);
  out->ix = cell.x;
  out->iy = cell.y;
  out->log_odds = value(cell);
  return true;
}

}  // namespace wavog
