#include "wavog_mapping/sim/wall_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <utility>

#include "wavog_mapping/sim/ground_truth.h"

namespace wavog {
namespace sim {
namespace {

constexpr double kFreeStep = 0.05;  // m between the free-side points checked against objects

// Raster index of a world point, or -1 outside.
long long indexAt(const Raster& r, const Vec2& p) {
  const auto ix = static_cast<std::int64_t>(std::floor(p.x() / r.cell_size)) - r.box.min_x;
  const auto iy = static_cast<std::int64_t>(std::floor(p.y() / r.cell_size)) - r.box.min_y;
  if (ix < 0 || iy < 0 || ix >= r.box.width() || iy >= r.box.height()) return -1;
  return iy * r.box.width() + ix;
}

// The raster's cells as a ground-truth window.
GridWindow windowOf(const Raster& map) {
  GridWindow window;
  window.resolution = map.cell_size;
  window.min_x = map.box.min_x;
  window.min_y = map.box.min_y;
  window.width = static_cast<int>(map.box.width());
  window.height = static_cast<int>(map.box.height());
  return window;
}

// The map's occupied cells: observed, log-odds above 1e-3 (above the unknown value's round-off).
bool occupied(const Raster& map, std::size_t i) { return map.known[i] && map.log_odds[i] > 1e-3f; }

// 1 where a cell lies within `margin_m` of a wall present at t and nearer to a wall than to any
// other object (so that cars parked against a wall do not count as the wall).
std::vector<std::uint8_t> nearWalls(const World& world, double t, const GridWindow& window,
                                    double margin_m) {
  const std::vector<std::uint8_t> walls = occupancyAt(world, t, window, TruthFilter::kWallsOnly);
  const std::vector<float> to_wall = distanceTransform(walls, window);
  std::vector<std::uint8_t> others = occupancyAt(world, t, window, TruthFilter::kAll);
  for (std::size_t i = 0; i < others.size(); ++i) others[i] = others[i] && !walls[i];
  const std::vector<float> to_other = distanceTransform(others, window);
  std::vector<std::uint8_t> near(window.size(), 0);
  for (std::size_t i = 0; i < window.size(); ++i) {
    near[i] = to_wall[i] <= margin_m && to_wall[i] < to_other[i];
  }
  return near;
}

// World-frame polygons of the walls present at t.
std::vector<Polygon> wallPolygons(const World& world, double t) {
  std::vector<Polygon> walls;
  for (const WorldObject& o : world.objects) {
    if (o.kind == ObjectKind::kWall && o.presentAt(t)) walls.push_back(o.polygonAt(t));
  }
  return walls;
}

// Distance from p to the nearest edge of the polygons (+inf without any).
double distanceToEdges(const std::vector<Polygon>& polygons, const Vec2& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const Polygon& poly : polygons) {
    for (std::size_t i = 0; i < poly.size(); ++i) {
      best = std::min(best, pointSegmentDistance(p, poly[i], poly[(i + 1) % poly.size()]));
    }
  }
  return best;
}

bool insideAny(const std::vector<Polygon>& polygons, const Vec2& p) {
  for (const Polygon& poly : polygons) {
    if (pointInPolygon(poly, p)) return true;
  }
  return false;
}

}  // namespace

std::vector<WallSample> wallSamplesFromWorld(const World& world, double t,
                                             const WallProfileOptions& options) {
  std::vector<WallSample> samples;
  const std::vector<Polygon> all = world.polygonsAt(t);
  for (const WorldObject& o : world.objects) {
    if (o.kind != ObjectKind::kWall || !o.presentAt(t)) continue;
    const Polygon poly = o.polygonAt(t);
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const Vec2& a = poly[i];
      const Vec2& b = poly[(i + 1) % poly.size()];
      const double length = (b - a).norm();
      if (length < options.min_length_m) continue;
      const Vec2 dir = (b - a) / length;
      Vec2 normal(-dir.y(), dir.x());
      if (pointInPolygon(poly, 0.5 * (a + b) + 0.01 * normal)) normal = -normal;
      for (double s = options.end_margin_m; s <= length - options.end_margin_m + 1e-9;
           s += options.spacing_m) {
        const Vec2 p = a + s * dir;
        bool free_side = true;
        for (double d = kFreeStep; d <= options.outside_m + 1e-9 && free_side; d += kFreeStep) {
          free_side = !insideAny(all, p + d * normal);
        }
        if (free_side) samples.push_back(WallSample{p, normal, false});
      }
    }
  }
  return samples;
}

std::vector<WallSample> wallSamplesFromMap(const Raster& reference,
                                           const WallProfileOptions& options, double radius_m,
                                           double min_linearity) {
  std::vector<WallSample> samples;
  const auto w = static_cast<int>(reference.box.width());
  const auto h = static_cast<int>(reference.box.height());
  auto occupied = [&reference, w](int x, int y) {
    const std::size_t i = static_cast<std::size_t>(y) * w + x;
    return reference.known[i] && reference.log_odds[i] > 0.0f;
  };
  const int r = std::max(1, static_cast<int>(std::lround(radius_m / reference.cell_size)));
  const double bucket = options.spacing_m / reference.cell_size;  // cells per bucket side
  std::set<std::pair<long long, long long>> taken;
  for (int y = r; y < h - r; ++y) {
    for (int x = r; x < w - r; ++x) {
      if (!occupied(x, y)) continue;
      const std::pair<long long, long long> key(static_cast<long long>(std::floor(x / bucket)),
                                                static_cast<long long>(std::floor(y / bucket)));
      if (taken.count(key)) continue;
      double n = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
      for (int dy = -r; dy <= r; ++dy) {
        for (int dx = -r; dx <= r; ++dx) {
          if (dx * dx + dy * dy > r * r || !occupied(x + dx, y + dy)) continue;
          n += 1;
          sx += dx;
          sy += dy;
          sxx += dx * dx;
          syy += dy * dy;
          sxy += dx * dy;
        }
      }
      if (n < r) continue;  // a line through the disc holds about 2r cells
      const double mx = sx / n, my = sy / n;
      const double cxx = sxx / n - mx * mx, cyy = syy / n - my * my, cxy = sxy / n - mx * my;
      // Eigenvalues of the 2x2 second-moment matrix.
      const double tr = cxx + cyy;
      const double disc = std::sqrt(std::max(0.0, 0.25 * (cxx - cyy) * (cxx - cyy) + cxy * cxy));
      const double major = 0.5 * tr + disc;
      const double minor = std::max(0.0, 0.5 * tr - disc);
      if (!(major > 0.0) || major < min_linearity * minor) continue;
      // Major axis direction; the normal is perpendicular to it.
      const double angle = 0.5 * std::atan2(2.0 * cxy, cxx - cyy);
      const Vec2 normal(-std::sin(angle), std::cos(angle));
      const Vec2 centre((reference.box.min_x + x + 0.5 + mx) * reference.cell_size,
                        (reference.box.min_y + y + 0.5 + my) * reference.cell_size);
      samples.push_back(WallSample{centre, normal, true});
      taken.insert(key);
    }
  }
  return samples;
}

WallWidth wallWidthAtHalfMax(const Raster& map, const std::vector<WallSample>& samples,
                             const WallProfileOptions& options) {
  WallWidth result;
  result.samples = samples.size();
  const double step = map.cell_size;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> widths;
  std::vector<double> profile;
  for (const WallSample& s : samples) {
    const double reach = std::max(options.inside_m, options.outside_m);
    const int lo = -static_cast<int>(std::ceil((s.two_sided ? reach : options.inside_m) / step));
    const int hi = static_cast<int>(std::ceil((s.two_sided ? reach : options.outside_m) / step));
    profile.assign(static_cast<std::size_t>(hi - lo + 1), nan);
    for (int k = lo; k <= hi; ++k) {
      const long long i = indexAt(map, s.point + (k * step) * s.normal);
      if (i >= 0 && map.known[static_cast<std::size_t>(i)]) {
        profile[static_cast<std::size_t>(k - lo)] =
            probabilityFromLogOdds(map.log_odds[static_cast<std::size_t>(i)]);
      }
    }
    // Peak near the surface, base on the free side (either side when two-sided).
    int peak_k = 0;
    double peak = -1.0;
    double base = 2.0;
    for (int k = lo; k <= hi; ++k) {
      const double v = profile[static_cast<std::size_t>(k - lo)];
      if (std::isnan(v)) continue;
      const double d = std::abs(k * step);
      if (d <= options.peak_window_m + 1e-9) {
        if (v > peak) {
          peak = v;
          peak_k = k;
        }
      } else if (s.two_sided || k > 0) {
        base = std::min(base, v);
      }
    }
    if (!(peak > 0.5) || !(base < peak)) continue;
    const double half = 0.5 * (peak + base);
    int width = 1;
    for (int k = peak_k - 1; k >= lo; --k) {
      const double v = profile[static_cast<std::size_t>(k - lo)];
      if (std::isnan(v) || v < half) break;
      ++width;
    }
    for (int k = peak_k + 1; k <= hi; ++k) {
      const double v = profile[static_cast<std::size_t>(k - lo)];
      if (std::isnan(v) || v < half) break;
      ++width;
    }
    widths.push_back(width);
  }
  result.measured = widths.size();
  if (widths.empty()) return result;
  double sum = 0.0;
  for (double v : widths) sum += v;
  result.mean_cells = sum / static_cast<double>(widths.size());
  std::sort(widths.begin(), widths.end());
  const std::size_t m = widths.size() / 2;
  result.median_cells = widths.size() % 2 ? widths[m] : 0.5 * (widths[m - 1] + widths[m]);
  return result;
}

double meanDistanceToWallSurface(const World& world, double t, const Raster& map, double margin_m,
                                 std::size_t* cells) {
  const GridWindow window = windowOf(map);
  const std::vector<float> to_surface =
      distanceTransform(surfaceAt(world, t, window, TruthFilter::kWallsOnly), window);
  const std::vector<std::uint8_t> near = nearWalls(world, t, window, margin_m);
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < window.size(); ++i) {
    if (!occupied(map, i) || !near[i]) continue;
    sum += to_surface[i];
    ++n;
  }
  if (cells) *cells = n;
  return n ? sum / static_cast<double>(n) : 0.0;
}

double distanceToWallEdges(const World& world, double t, const Vec2& p) {
  return distanceToEdges(wallPolygons(world, t), p);
}

NdtWallDistance ndtWallDistance(const World& world, double t, const Raster& map,
                                const NdtLayer& ndt, double margin_m) {
  NdtWallDistance d;
  if (!ndt.cells.empty() && !(std::fabs(ndt.cell_size - map.cell_size) <= 1e-9 * map.cell_size)) {
    throw std::invalid_argument("ndtWallDistance: Gaussians of another cell size than the map's");
  }
  const GridWindow window = windowOf(map);
  const std::vector<std::uint8_t> near = nearWalls(world, t, window, margin_m);
  const std::vector<Polygon> walls = wallPolygons(world, t);  // once, not per point
  double centres = 0.0;
  for (std::size_t i = 0; i < window.size(); ++i) {
    if (!occupied(map, i) || !near[i]) continue;
    const int col = static_cast<int>(i % static_cast<std::size_t>(window.width));
    const int row = static_cast<int>(i / static_cast<std::size_t>(window.width));
    centres += distanceToEdges(walls, window.centre(col, row));
    ++d.cells;
  }
  if (d.cells > 0) d.cell_centre_m = centres / static_cast<double>(d.cells);
  double ndt_centres = 0.0;
  double means = 0.0;
  for (const NdtCell& c : ndt.cells) {
    const std::int64_t col = c.ix - map.box.min_x;
    const std::int64_t row = c.iy - map.box.min_y;
    if (col < 0 || row < 0 || col >= map.box.width() || row >= map.box.height()) continue;
    const auto i = static_cast<std::size_t>(row * map.box.width() + col);
    if (!occupied(map, i) || !near[i]) continue;
    ndt_centres +=
        distanceToEdges(walls, window.centre(static_cast<int>(col), static_cast<int>(row)));
    means += distanceToEdges(walls, Vec2(c.mean_x, c.mean_y));
    ++d.gaussians;
  }
  if (d.gaussians > 0) {
    d.ndt_cell_centre_m = ndt_centres / static_cast<double>(d.gaussians);
    d.ndt_mean_m = means / static_cast<double>(d.gaussians);
  }
  return d;
}

}  // namespace sim
}  // namespace wavog
