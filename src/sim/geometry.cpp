#include "wavog_mapping/sim/geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace wavog {
namespace sim {

Polygon makeBox(double length, double width) {
  return makeRect(-length / 2, -width / 2, length / 2, width / 2);
}

Polygon makeRect(double min_x, double min_y, double max_x, double max_y) {
  return {Vec2(min_x, min_y), Vec2(max_x, min_y), Vec2(max_x, max_y), Vec2(min_x, max_y)};
}

Polygon makeRegular(int n, double radius) {
  Polygon poly;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * M_PI * i / n;
    poly.emplace_back(radius * std::cos(a), radius * std::sin(a));
  }
  return poly;
}

Vec2 transformPoint(const Pose2& pose, const Vec2& p) {
  const double c = std::cos(pose.theta);
  const double s = std::sin(pose.theta);
  return Vec2(pose.x + c * p.x() - s * p.y(), pose.y + s * p.x() + c * p.y());
}

Polygon transformed(const Polygon& local, const Pose2& pose) {
  Polygon out;
  out.reserve(local.size());
  for (const Vec2& p : local) out.push_back(transformPoint(pose, p));
  return out;
}

bool pointInPolygon(const Polygon& poly, const Vec2& p) {
  bool inside = false;
  const std::size_t n = poly.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y())) {
      const double x_cross = a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
      if (p.x() < x_cross) inside = !inside;
    }
  }
  return inside;
}

double pointSegmentDistance(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

double pointPolygonDistance(const Polygon& poly, const Vec2& p) {
  if (pointInPolygon(poly, p)) return 0.0;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    best = std::min(best, pointSegmentDistance(p, poly[j], poly[i]));
  }
  return best;
}

double raySegmentDistance(const Vec2& origin, const Vec2& dir, const Vec2& a, const Vec2& b) {
  // Solve origin + t*dir = a + u*(b-a) with Cramer's rule; 2D cross products.
  const Vec2 e = b - a;
  const double denom = dir.x() * e.y() - dir.y() * e.x();
  if (denom == 0.0) return std::numeric_limits<double>::infinity();
  const Vec2 w = a - origin;
  const double t = (w.x() * e.y() - w.y() * e.x()) / denom;
  const double u = (w.x() * dir.y() - w.y() * dir.x()) / denom;
  if (t < 0.0 || u < 0.0 || u > 1.0) return std::numeric_limits<double>::infinity();
  return t;
}

bool polygonsIntersect(const Polygon& a, const Polygon& b) {
  auto cross = [](const Vec2& u, const Vec2& v) { return u.x() * v.y() - u.y() * v.x(); };
  // Proper or touching crossing of segments [p, q] and [r, s].
  auto segments_cross = [&cross](const Vec2& p, const Vec2& q, const Vec2& r, const Vec2& s) {
    const double d1 = cross(q - p, r - p);
    const double d2 = cross(q - p, s - p);
    const double d3 = cross(s - r, p - r);
    const double d4 = cross(s - r, q - r);
    return d1 * d2 <= 0.0 && d3 * d4 <= 0.0 && !(d1 == 0.0 && d2 == 0.0);
  };
  for (std::size_t i = 0, j = a.size() - 1; i < a.size(); j = i++) {
    for (std::size_t k = 0, l = b.size() - 1; k < b.size(); l = k++) {
      if (segments_cross(a[j], a[i], b[l], b[k])) return true;
    }
  }
  return pointInPolygon(a, b.front()) || pointInPolygon(b, a.front());
}

void boundingBox(const Polygon& poly, Vec2* min, Vec2* max) {
  *min = Vec2::Constant(std::numeric_limits<double>::infinity());
  *max = -*min;
  for (const Vec2& p : poly) {
    *min = min->cwiseMin(p);
    *max = max->cwiseMax(p);
  }
}

}  // namespace sim
}  // namespace wavog
