// Multiscale read-out: dense rasters of a window at scale s (mean = Haar average, or max over
// observed cells) and their OccupancyGrid values. Read-only: lazy tags are applied on the way down
// (ALGORITHM.md F3), nothing is written.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "storage/map_impl.h"
#include "wavog_mapping/core/haar.h"
#include "wavog_mapping/core/limits.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog {
namespace {

using detail::Block;
using detail::Node;

constexpr float kNoObservedCell = -std::numeric_limits<float>::infinity();

class RasterWriter {
 public:
  RasterWriter(const WaveletMap::Impl& impl, Raster* out, Aggregation agg)
      : impl_(impl), out_(out), agg_(agg), s_(out->scale) {}

  // Fills the raster cells covered by the slot at level l (origin ix0/iy0 in finest cells),
  // average `avg`, node `n` (null: uniform), knowledge bits, details multiplier `mult`.
  void slot(const Node* n, int l, std::int64_t ix0, std::int64_t iy0, double avg, double mult,
            bool all, bool any) {
    // The slot's extent in raster cells.
    const std::int64_t rx0 = ix0 >> s_, ry0 = iy0 >> s_;
    const std::int64_t span = l >= s_ ? (std::int64_t{1} << (l - s_)) : 1;
    const CellBox& w = out_->box;
    if (rx0 + span <= w.min_x || rx0 >= w.max_x || ry0 + span <= w.min_y || ry0 >= w.max_y) return;
    if (l == s_ || n == nullptr) {
      float v = static_cast<float>(avg);
      if (agg_ == Aggregation::kMax) {
        v = n == nullptr ? (any ? v : kNoObservedCell) : maxObserved(*n, l, avg, mult);
      }
      (void)all;
      fill(rx0, ry0, span, v, any);
      return;
    }
    const double m = mult * impl_.multiplier(n->k);
    if (impl_.hasTile(*n)) {
      impl_.withTile(*n, [&](const auto& t) { tile(t, l, ix0, iy0, avg, m); });
      return;
    }
    const double d[3] = {n->d[0] * m, n->d[1] * m, n->d[2] * m};
    const auto c = haar::backward(avg, d);
    const std::int64_t half = std::int64_t{1} << (l - 1);
    for (int q = 0; q < 4; ++q) {
      const bool has = l > 1 && impl_.hasChild(*n, q);
      slot(has ? &impl_.child(*n, q) : nullptr, l - 1, ix0 + ((q & 1) ? half : 0),
           iy0 + ((q & 2) ? half : 0), c[static_cast<std::size_t>(q)], m, (n->known_all >> q) & 1u,
           (n->known_any >> q) & 1u);
    }
  }

 private:
  // The raster cells of a tile of level l > s_ (origin ix0, iy0; its node's average avg, the
  // factor of its values m): each the mean, or the max over the observed, of its cells.
  template <typename Tile>
  void tile(const Tile& t, int l, std::int64_t ix0, std::int64_t iy0, double avg, double m) {
    const unsigned side = 1u << s_, n = 1u << l;
    for (unsigned y = 0; y < n; y += side) {
      for (unsigned x = 0; x < n; x += side) {
        const std::uint64_t cells = detail::tileSquare(s_, x, y), known = t.known & cells;
        float v = static_cast<float>(avg + m * (detail::tileMean(t, cells) - t.base));
        if (agg_ == Aggregation::kMax) v = maxOf(t, known, avg, m);
        fill((ix0 + x) >> s_, (iy0 + y) >> s_, 1, v, known != 0);
      }
    }
  }

  // Max over the cells `known` of a tile (its node's average avg, the factor of its values m).
  template <typename Tile>
  static float maxOf(const Tile& t, std::uint64_t known, double avg, double m) {
    float best = kNoObservedCell;
    for (; known != 0; known &= known - 1) {
      const double v = avg + m * (t.v[__builtin_ctzll(known)] - t.base);
      best = std::max(best, static_cast<float>(v));
    }
    return best;
  }

  // Max over the observed finest cells below node n (level l, average avg).
  float maxObserved(const Node& n, int l, double avg, double mult) const {
    const double m = mult * impl_.multiplier(n.k);
    if (impl_.hasTile(n)) {
      return impl_.withTile(n, [&](const auto& t) { return maxOf(t, t.known, avg, m); });
    }
    const double d[3] = {n.d[0] * m, n.d[1] * m, n.d[2] * m};
    const auto c = haar::backward(avg, d);
    float best = kNoObservedCell;
    for (int q = 0; q < 4; ++q) {
      const auto cq = static_cast<float>(c[static_cast<std::size_t>(q)]);
      if (l > 1 && impl_.hasChild(n, q)) {
        best = std::max(best,
                        maxObserved(impl_.child(n, q), l - 1, c[static_cast<std::size_t>(q)], m));
      } else if ((n.known_any >> q) & 1u) {
        best = std::max(best, cq);
      }
    }
    return best;
  }

  void fill(std::int64_t rx0, std::int64_t ry0, std::int64_t span, float v, bool any) {
    const CellBox& w = out_->box;
    const std::int64_t x0 = std::max(rx0, w.min_x), x1 = std::min(rx0 + span, w.max_x);
    const std::int64_t y0 = std::max(ry0, w.min_y), y1 = std::min(ry0 + span, w.max_y);
    const auto width = static_cast<std::size_t>(w.width());
    for (std::int64_t y = y0; y < y1; ++y) {
      const std::size_t row = static_cast<std::size_t>(y - w.min_y) * width;
      for (std::int64_t x = x0; x < x1; ++x) {
        const std::size_t i = row + static_cast<std::size_t>(x - w.min_x);
        if (any) {
          out_->log_odds[i] = v;
          out_->known[i] = 1;
        }
      }
    }
  }

  const WaveletMap::Impl& impl_;
  Raster* out_;
  Aggregation agg_;
  int s_;
};

}  // namespace

double probabilityFromLogOdds(float log_odds) {
  return 1.0 / (1.0 + std::exp(-static_cast<double>(log_odds)));
}

std::int8_t occupancyFromLogOdds(float log_odds) {
  if (std::isnan(log_odds)) return -1;
  return static_cast<std::int8_t>(std::lround(100.0 * probabilityFromLogOdds(log_odds)));
}

std::vector<std::int8_t> toOccupancyGrid(const Raster& raster) {
  std::vector<std::int8_t> out(raster.log_odds.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = raster.known[i] ? occupancyFromLogOdds(raster.log_odds[i]) : std::int8_t{-1};
  }
  return out;
}

std::int8_t gridValue(float log_odds, bool known, const GridValues& values) {
  if (!known) return -1;
  if (!values.trinary) return occupancyFromLogOdds(log_odds);
  if (std::isnan(log_odds)) return -1;
  const double p = probabilityFromLogOdds(log_odds);
  if (p > values.occupied_thresh) return 100;
  if (p < values.free_thresh) return 0;
  return -1;
}

std::vector<std::int8_t> toOccupancyGrid(const Raster& raster, const GridValues& values) {
  std::vector<std::int8_t> out(raster.log_odds.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = gridValue(raster.log_odds[i], raster.known[i] != 0, values);
  }
  return out;
}

bool WaveletMap::bounds(int scale, CellBox* box) const {
  const Impl& impl = *impl_;
  if (impl.blocks.empty()) return false;
  std::int64_t x0 = std::numeric_limits<std::int64_t>::max(), y0 = x0;
  std::int64_t x1 = std::numeric_limits<std::int64_t>::min(), y1 = x1;
  for (const auto& kv : impl.blocks) {
    const std::int64_t bx = detail::blockKeyX(kv.first), by = detail::blockKeyY(kv.first);
    x0 = std::min(x0, bx);
    y0 = std::min(y0, by);
    x1 = std::max(x1, bx + 1);
    y1 = std::max(y1, by + 1);
  }
  const int shift = impl.levels - std::clamp(scale, 0, impl.levels);
  *box = CellBox{detail::scaleUp(x0, shift), detail::scaleUp(y0, shift), detail::scaleUp(x1, shift),
                 detail::scaleUp(y1, shift)};
  return true;
}

CellBox WaveletMap::boxAround(double min_x, double min_y, double max_x, double max_y,
                              int scale) const {
  if (std::isnan(min_x) || std::isnan(min_y) || std::isnan(max_x) || std::isnan(max_y)) {
    return CellBox{};
  }
  const double cell = std::ldexp(impl_->params.grid.resolution, std::clamp(scale, 0, 62));
  return CellBox{clampedCellIndex(std::floor(min_x / cell)),
                 clampedCellIndex(std::floor(min_y / cell)),
                 clampedCellIndex(std::floor(max_x / cell)) + 1,
                 clampedCellIndex(std::floor(max_y / cell)) + 1};
}

Raster WaveletMap::exportScale(int scale, const CellBox& window, Aggregation aggregation) const {
  const Impl& impl = *impl_;
  Raster r;
  r.scale = std::clamp(scale, 0, impl.levels);
  r.cell_size = std::ldexp(impl.params.grid.resolution, r.scale);
  r.box = window;
  if (window.empty()) {
    r.box = CellBox{};
    return r;
  }
  const std::uint64_t cells = readoutCells(window);
  if (cells > kMaxReadoutCells) {
    // Width and height as unsigned differences: exact for any window.
    throw ReadoutTooLarge("read-out of " +
                          std::to_string(static_cast<std::uint64_t>(window.max_x) -
                                         static_cast<std::uint64_t>(window.min_x)) +
                          " x " +
                          std::to_string(static_cast<std::uint64_t>(window.max_y) -
                                         static_cast<std::uint64_t>(window.min_y)) +
                          " cells at scale " + std::to_string(r.scale) + " refused: more than " +
                          std::to_string(kMaxReadoutCells) + " cells (kMaxReadoutCells)");
  }
  const auto count = static_cast<std::size_t>(cells);
  r.log_odds.assign(count, static_cast<float>(impl.init));
  r.known.assign(count, 0);
  RasterWriter writer(impl, &r, aggregation);
  const int shift = impl.levels - r.scale;  // raster cells per block side = 2^shift
  const std::int64_t bx0 = window.min_x >> shift, bx1 = (window.max_x - 1) >> shift;
  const std::int64_t by0 = window.min_y >> shift, by1 = (window.max_y - 1) >> shift;
  const auto visit = [&](std::int64_t bx, std::int64_t by, const Block& b) {
    writer.slot(b.has_root ? &b.root : nullptr, impl.levels, detail::scaleUp(bx, impl.levels),
                detail::scaleUp(by, impl.levels), b.s, 1.0, b.known_all, b.known_any);
  };
  // Look the window's blocks up, or walk the hash when the window is larger than the map.
  const double window_blocks =
      static_cast<double>(bx1 - bx0 + 1) * static_cast<double>(by1 - by0 + 1);
  if (window_blocks <= static_cast<double>(impl.blocks.size())) {
    for (std::int64_t by = by0; by <= by1; ++by) {
      for (std::int64_t bx = bx0; bx <= bx1; ++bx) {
        if (const Block* b = impl.findBlock(bx, by)) visit(bx, by, *b);
      }
    }
  } else {
    for (const auto& kv : impl.blocks) {
      const std::int64_t bx = detail::blockKeyX(kv.first), by = detail::blockKeyY(kv.first);
      if (bx < bx0 || bx > bx1 || by < by0 || by > by1) continue;
      visit(bx, by, kv.second);
    }
  }
  return r;
}

}  // namespace wavog
