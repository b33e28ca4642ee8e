#include "wavog_mapping/sim/wall_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <utility>

#include "wavog_mapping/sim/ground_truth.h"

namespace wavog {
namespace sim {
namespace {

constexpr double kFreeStep = 0.05;  // m between the free-side points checked against objects

double probability(float log_odds) {
  return 1.0 / (1.0 + std::exp(-static_cast<double>(log_odds)));
}

// Raster index of a world point, or -1 outside.
long long indexAt(const Raster& r, const Vec2& p) {
  const auto ix = static_cast<std::int64_t>(std::floor(p.x() / r.cell_size)) - r.box.min_x;
  const auto iy = static_cast<std::int64_t>(std::floor(p.y() / r.cell_size)) - r.box.min_y;
  if (ix < 0 || iy < 0 || ix >= r.box.width() || iy >= r.box.height()) return -1;
  return iy * r.box.width() + ix;
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
            probability(map.log_odds[static_cast<std::size_t>(i)]);
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
  GridWindow window;
  window.resolution = map.cell_size;
  window.min_x = map.box.min_x;
  window.min_y = map.box.min_y;
  window.width = static_cast<int>(map.box.width());
  window.height = static_cast<int>(map.box.height());
  const std::vector<float> to_surface =
      distanceTransform(surfaceAt(world, t, window, TruthFilter::kWallsOnly), window);
  const std::vector<std::uint8_t> walls = occupancyAt(world, t, window, TruthFilter::kWallsOnly);
  const std::vector<float> to_wall = distanceTransform(walls, window);
  std::vector<std::uint8_t> others = occupancyAt(world, t, window, TruthFilter::kAll);
  for (std::size_t i = 0; i < others.size(); ++i) others[i] = others[i] && !walls[i];
  const std::vector<float> to_other = distanceTransform(others, window);
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < window.size(); ++i) {
    if (!map.known[i] || !(map.log_odds[i] > 1e-3f)) continue;
    if (to_wall[i] <= margin_m && to_wall[i] < to_other[i]) {
      sum += to_surface[i];
      ++n;
    }
  }
  if (cells) *cells = n;
  return n ? sum / static_cast<double>(n) : 0.0;
}

}  // namespace sim
}  // namespace wavog
