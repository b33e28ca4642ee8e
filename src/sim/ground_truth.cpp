#include "wavog_mapping/sim/ground_truth.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace wavog {
namespace sim {
namespace {

std::vector<Polygon> selectPolygons(const World& world, double t, TruthFilter filter) {
  std::vector<int> owners;
  std::vector<Polygon> all = world.polygonsAt(t, &owners);
  if (filter == TruthFilter::kAll) return all;
  std::vector<Polygon> out;
  for (std::size_t i = 0; i < all.size(); ++i) {
    if (world.objects[static_cast<std::size_t>(owners[i])].kind == ObjectKind::kWall) {
      out.push_back(all[i]);
    }
  }
  return out;
}

// One-dimensional squared distance transform of f into d: the lower envelope of the parabolas
// (q - p)^2 + f[p] (Felzenszwalb & Huttenlocher, "Distance transforms of sampled functions").
// v holds the envelope's parabola apexes, z the boundaries between them; both are scratch space.
void distance1d(const std::vector<double>& f, std::vector<double>* d, std::vector<int>* v,
                std::vector<double>* z) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const int n = static_cast<int>(f.size());
  auto meet = [&f](int q, int p) {  // where parabolas apexed at q and p intersect
    return ((f[q] + q * q) - (f[p] + p * p)) / (2.0 * (q - p));
  };
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (!std::isfinite(f[q])) continue;
    while (k >= 0 && meet(q, (*v)[k]) <= (*z)[k]) --k;
    ++k;
    (*v)[k] = q;
    (*z)[k] = k == 0 ? -kInf : meet(q, (*v)[k - 1]);
    (*z)[k + 1] = kInf;
  }
  for (int q = 0, j = 0; q < n; ++q) {
    if (k < 0) {
      (*d)[q] = kInf;
      continue;
    }
    while ((*z)[j + 1] < q) ++j;
    const int p = (*v)[j];
    (*d)[q] = (q - p) * (q - p) + f[p];
  }
}

}  // namespace

GridWindow GridWindow::covering(const Vec2& min, const Vec2& max, double resolution) {
  GridWindow w;
  w.resolution = resolution;
  w.min_x = static_cast<std::int64_t>(std::floor(min.x() / resolution));
  w.min_y = static_cast<std::int64_t>(std::floor(min.y() / resolution));
  w.width = static_cast<int>(std::floor(max.x() / resolution) - w.min_x + 1);
  w.height = static_cast<int>(std::floor(max.y() / resolution) - w.min_y + 1);
  return w;
}

Vec2 GridWindow::centre(int col, int row) const {
  return Vec2((static_cast<double>(min_x + col) + 0.5) * resolution,
              (static_cast<double>(min_y + row) + 0.5) * resolution);
}

bool GridWindow::locate(const Vec2& p, int* col, int* row) const {
  const double cx = std::floor(p.x() / resolution) - static_cast<double>(min_x);
  const double cy = std::floor(p.y() / resolution) - static_cast<double>(min_y);
  if (!(cx >= 0 && cy >= 0 && cx < width && cy < height)) return false;
  *col = static_cast<int>(cx);
  *row = static_cast<int>(cy);
  return true;
}

std::vector<std::uint8_t> rasteriseFilled(const std::vector<Polygon>& polygons,
                                          const GridWindow& window) {
  std::vector<std::uint8_t> out(window.size(), 0);
  for (const Polygon& poly : polygons) {
    Vec2 lo, hi;
    boundingBox(poly, &lo, &hi);
    const GridWindow box = GridWindow::covering(lo, hi, window.resolution);
    for (int r = 0; r < box.height; ++r) {
      for (int c = 0; c < box.width; ++c) {
        const Vec2 p = box.centre(c, r);
        int col = 0, row = 0;
        if (window.locate(p, &col, &row) && pointInPolygon(poly, p))
          out[window.index(col, row)] = 1;
      }
    }
  }
  return out;
}

std::vector<std::uint8_t> rasteriseBoundary(const std::vector<Polygon>& polygons,
                                            const GridWindow& window) {
  // Sample each edge at a quarter cell: every cell the edge crosses gets a sample except where it
  // only clips a corner by less than that.
  std::vector<std::uint8_t> out(window.size(), 0);
  const double step = window.resolution / 4;
  for (const Polygon& poly : polygons) {
    for (std::size_t k = 0, j = poly.size() - 1; k < poly.size(); j = k++) {
      const Vec2 a = poly[j];
      const Vec2 b = poly[k];
      const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
      for (int i = 0; i <= n; ++i) {
        int col = 0, row = 0;
        if (window.locate(a + (b - a) * (static_cast<double>(i) / n), &col, &row)) {
          out[window.index(col, row)] = 1;
        }
      }
    }
  }
  return out;
}

std::vector<std::uint8_t> occupancyAt(const World& world, double t, const GridWindow& window,
                                      TruthFilter filter) {
  return rasteriseFilled(selectPolygons(world, t, filter), window);
}

std::vector<std::uint8_t> surfaceAt(const World& world, double t, const GridWindow& window,
                                    TruthFilter filter) {
  return rasteriseBoundary(selectPolygons(world, t, filter), window);
}

std::vector<float> distanceTransform(const std::vector<std::uint8_t>& mask,
                                     const GridWindow& window) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const int w = window.width;
  const int h = window.height;
  std::vector<double> grid(window.size());
  for (std::size_t i = 0; i < grid.size(); ++i) grid[i] = mask[i] ? 0.0 : kInf;
  const int n = std::max(w, h);
  std::vector<double> f(static_cast<std::size_t>(n)), d(static_cast<std::size_t>(n));
  std::vector<int> v(static_cast<std::size_t>(n));
  std::vector<double> z(static_cast<std::size_t>(n) + 1);
  // Columns, then rows (the transform is separable).
  for (int c = 0; c < w; ++c) {
    f.resize(static_cast<std::size_t>(h));
    d.resize(static_cast<std::size_t>(h));
    for (int r = 0; r < h; ++r) f[static_cast<std::size_t>(r)] = grid[window.index(c, r)];
    distance1d(f, &d, &v, &z);
    for (int r = 0; r < h; ++r) grid[window.index(c, r)] = d[static_cast<std::size_t>(r)];
  }
  for (int r = 0; r < h; ++r) {
    f.resize(static_cast<std::size_t>(w));
    d.resize(static_cast<std::size_t>(w));
    for (int c = 0; c < w; ++c) f[static_cast<std::size_t>(c)] = grid[window.index(c, r)];
    distance1d(f, &d, &v, &z);
    for (int c = 0; c < w; ++c) grid[window.index(c, r)] = d[static_cast<std::size_t>(c)];
  }
  std::vector<float> out(window.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = static_cast<float>(std::sqrt(grid[i]) * window.resolution);
  }
  return out;
}

}  // namespace sim
}  // namespace wavog
