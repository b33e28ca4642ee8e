// Planar geometry of the simulator: polygons, exact ray casting, point-in-polygon, distances.
// Units: metres, radians; all in one frame chosen by the caller. Pure functions, thread-safe.
#ifndef WAVOG_MAPPING_SIM_GEOMETRY_H_
#define WAVOG_MAPPING_SIM_GEOMETRY_H_

#include <Eigen/Core>
#include <vector>

#include "wavog_mapping/core/types.h"

namespace wavog {
namespace sim {

using Vec2 = Eigen::Vector2d;
/// A simple polygon, vertices in order (either orientation), closed implicitly.
using Polygon = std::vector<Vec2, Eigen::aligned_allocator<Vec2>>;

/// Rectangle of `length` (along x) by `width` centred on the origin.
Polygon makeBox(double length, double width);
/// Rectangle with corners (min_x, min_y) and (max_x, max_y).
Polygon makeRect(double min_x, double min_y, double max_x, double max_y);
/// Regular n-gon of circumradius `radius` centred on the origin (n >= 3).
Polygon makeRegular(int n, double radius);

/// `local` expressed in the frame where `pose` is the pose of the polygon's frame.
Polygon transformed(const Polygon& local, const Pose2& pose);
/// Point `p` (given in the frame of `pose`) expressed in the parent frame.
Vec2 transformPoint(const Pose2& pose, const Vec2& p);
// compose() and wrapAngle(): the core's (wavog_mapping/core/types.h).

/// True if `p` lies inside `poly` (even-odd rule; points exactly on an edge may go either way).
bool pointInPolygon(const Polygon& poly, const Vec2& p);
/// Distance from `p` to segment [a, b].
double pointSegmentDistance(const Vec2& p, const Vec2& a, const Vec2& b);
/// Distance from `p` to the boundary of `poly`; 0 if `p` is inside.
double pointPolygonDistance(const Polygon& poly, const Vec2& p);
/// Distance along the ray origin + t * dir (dir unit length, t >= 0) to segment [a, b], or
/// +inf if the ray misses it. A ray through an endpoint hits. Parallel overlaps count as misses
/// (the adjacent edges of a polygon then give the hit).
double raySegmentDistance(const Vec2& origin, const Vec2& dir, const Vec2& a, const Vec2& b);
/// True if the two polygons overlap (an edge crossing, or one inside the other).
bool polygonsIntersect(const Polygon& a, const Polygon& b);
/// Axis-aligned bounding box of a polygon, as (min, max).
void boundingBox(const Polygon& poly, Vec2* min, Vec2* max);

}  // namespace sim
}  // namespace wavog

#endif  // WAVOG_MAPPING_SIM_GEOMETRY_H_
