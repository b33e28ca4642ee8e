// Read-out of the normal-distribution cells (MapParams::ndt, paper section 1.2.3): the Gaussians
// of one window at scale s, each merging the moments of the finest cells under it exactly (the
// parallel-axis shift of each cell's moments to the coarse cell's centre, in double), and the
// Gaussian of one finest cell. Storage: ndt_store.h; update: ndt_update.h.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "storage/map_impl.h"
#include "wavog_mapping/core/limits.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog {

using detail::Block;
using detail::NdtEntry;
using detail::NdtMoments;

namespace {

void requireNdt(const WaveletMap::Impl& impl) {
  if (!impl.params.ndt) {
    throw std::logic_error("this map keeps no normal-distribution cells (MapParams::ndt)");
  }
}

// The Gaussian of moments `m` about the point (cx, cy) of the map frame.
NdtCell gaussian(const NdtMoments& m, double cx, double cy) {
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

}  // namespace

NdtAxes principalAxes(double cov_xx, double cov_xy, double cov_yy) {
  // Eigenvalues of a symmetric 2x2: mean +- radius; the major axis at half the angle of
  // (xx - yy, 2 xy).
  const double mean = 0.5 * (cov_xx + cov_yy);
  const double radius = std::hypot(0.5 * (cov_xx - cov_yy), cov_xy);
  NdtAxes axes;
  axes.sigma_major = std::sqrt(std::max(0.0, mean + radius));
  axes.sigma_minor = std::sqrt(std::max(0.0, mean - radius));
  axes.yaw = 0.5 * std::atan2(2.0 * cov_xy, cov_xx - cov_yy);
  return axes;
}

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
      if (!detail::NdtCells::live(e)) continue;
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
    NdtMoments sum;
    for (; i < items.size() && items[i].cx == cx && items[i].cy == cy; ++i) {
      const double ox = (static_cast<double>(items[i].ix) + 0.5) * r - ccx;
      const double oy = (static_cast<double>(items[i].iy) + 0.5) * r - ccy;
      sum.addShifted(*items[i].m, ox, oy);
    }
    NdtCell c = gaussian(sum, ccx, ccy);
    c.ix = cx;
    c.iy = cy;
    c.log_odds = static_cast<float>(impl.read(scale, cx, cy).average);
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
  if (e == nullptr || !detail::NdtCells::live(*e)) return false;
  const double r = impl.params.grid.resolution;
  *out = gaussian(e->m, (static_cast<double>(cell.x) + 0.5) * r,
                  (static_cast<double>(cell.y) + 0.5) * r);
  out->ix = cell.x;
  out->iy = cell.y;
  out->log_odds = value(cell);
  return true;
}

}  // namespace wavog
