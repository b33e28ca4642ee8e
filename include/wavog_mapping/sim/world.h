// The simulated world: 2D polygons (walls, parked cars, moving cars, pedestrians) that may appear,
// disappear and move along timed trajectories, and a vehicle carrying planar lasers along a path.
// Frames: everything in the world ("map") frame; object shapes and laser mounts in their parent's
// frame. Units: metres, radians, seconds. Plain values; const access is thread-safe.
#ifndef WAVOG_MAPPING_SIM_WORLD_H_
#define WAVOG_MAPPING_SIM_WORLD_H_

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "wavog_mapping/core/types.h"
#include "wavog_mapping/sim/geometry.h"

namespace wavog {
namespace sim {

/// A pose at a time.
struct Waypoint {
  double t = 0.0;  ///< time (s)
  Pose2 pose;      ///< pose in the parent frame
};

/// A piecewise-linear timed path (positions and headings interpolated, headings the short way
/// round); held at its first pose before the first waypoint and its last pose after the last.
struct Trajectory {
  std::vector<Waypoint> waypoints;  ///< strictly increasing times
  bool empty() const { return waypoints.empty(); }
  /// Pose at time t (identity for an empty trajectory).
  Pose2 at(double t) const;

  /// A path through `points` at constant `speed` (m/s) starting at `t0`, heading along the path.
  /// Corners are rounded with `corner_radius` (m) so the heading turns smoothly.
  static Trajectory fromRoute(const std::vector<Vec2, Eigen::aligned_allocator<Vec2>>& points,
                              double speed, double t0, double corner_radius = 0.0);
};

/// What an object is; the evaluation treats walls as the map's static structure.
enum class ObjectKind { kWall, kCar, kPedestrian, kObstacle };
/// What an object does in the scenario; departing/arriving cars define the responsiveness events.
enum class ObjectRole { kStatic, kMoving, kDeparting, kArriving };

const char* toString(ObjectKind kind);
const char* toString(ObjectRole role);
bool fromString(const std::string& name, ObjectKind* kind);
bool fromString(const std::string& name, ObjectRole* role);

/// One rigid polygonal object, present during [appear_time, disappear_time).
struct WorldObject {
  std::string name;
  ObjectKind kind = ObjectKind::kObstacle;
  ObjectRole role = ObjectRole::kStatic;
  Polygon shape;          ///< in the object frame; the world frame if `trajectory` is empty
  Trajectory trajectory;  ///< pose of the object frame over time; empty: static identity
  double appear_time = -std::numeric_limits<double>::infinity();    ///< (s)
  double disappear_time = std::numeric_limits<double>::infinity();  ///< (s)

  bool presentAt(double t) const { return t >= appear_time && t < disappear_time; }
  /// The shape in the world frame at time t (regardless of presence).
  Polygon polygonAt(double t) const;
};

/// A simulated planar laser (defaults: SICK LMS-291, 180 deg at 0.5 deg, 80 m, 40 Hz).
struct LaserParams {
  std::string name = "laser";      ///< short name, e.g. "front_left"
  std::string frame_id = "laser";  ///< tf frame of the scans (no leading slash)
  std::string topic = "scan";      ///< bag topic of the scans
  Pose2 mount;                     ///< pose in the vehicle (base_link) frame
  int beams = 361;                 ///< number of beams, >= 2
  double fov = M_PI;               ///< angular span from first to last beam (rad)
  double range_min = 0.0;          ///< readings below are invalid (m)
  double range_max = 80.0;         ///< no return at or beyond (m)
  double rate_hz = 40.0;           ///< scans per second
  double phase_s = 0.0;            ///< time of the first scan (s), staggers the lasers
  double noise_sigma = 0.02;       ///< standard deviation of the Gaussian range noise (m)
  double dropout_prob = 0.002;     ///< probability of a NaN reading per beam
  double angleMin() const { return -fov / 2; }
  double angleIncrement() const { return fov / (beams - 1); }
};

/// The ego vehicle: a path and its lasers. Its own body is not seen by its lasers.
struct Vehicle {
  Polygon footprint;  ///< in base_link, for drawing only
  Trajectory path;    ///< pose of base_link in the world frame
  std::vector<LaserParams> lasers;
};

/// A scenario: objects, the vehicle, a duration and a region of interest for maps and metrics.
struct World {
  std::string name = "world";
  double duration = 60.0;        ///< scans are produced for t in [0, duration) (s)
  Vec2 region_min = Vec2(0, 0);  ///< region of interest, for ground truth and pictures (m)
  Vec2 region_max = Vec2(10, 10);
  std::vector<WorldObject> objects;
  Vehicle vehicle;

  /// World-frame polygons of the objects present at time t, and the index of each in `objects`
  /// (if `owners` is given).
  std::vector<Polygon> polygonsAt(double t, std::vector<int>* owners = nullptr) const;
  /// Every violated rule, one line each (empty: valid).
  std::vector<std::string> validate() const;
};

/// Pose of a LMS-291 mounted at a corner of a `length` x `width` vehicle, facing outwards at 45
/// deg. corner: 0 front-left, 1 front-right, 2 rear-left, 3 rear-right.
LaserParams cornerLaser(int corner, double length, double width);

/// The built-in default scenario: a car park (walls, rows of parked cars, one car leaving, one
/// arriving, a crossing car, a pedestrian) and a truck with four LMS-291 at its corners driving
/// through it. `duration` (s) shortens or lengthens the run; events keep their times.
World defaultWorld(double duration = 60.0);

/// Vehicle `k` of a fleet of `n` (0 <= k < n) in `world`: the same lasers on the same route, started
/// k / n of a lap further along it (a lap: half the route's duration, the car park's truck drives
/// its loop twice), so that n vehicles spread over the site. Vehicle 0 is `world` unchanged.
/// Throws std::invalid_argument for k outside [0, n).
World fleetMember(const World& world, int k, int n);

/// A small scenario for tests: one laser at rest facing a wall, one parked car in between that
/// vanishes at `depart_time`. `duration` sets the number of scans (rate 40 Hz).
World testWorld(double depart_time, double duration, double noise_sigma = 0.0);

}  // namespace sim
}  // namespace wavog

#endif  // WAVOG_MAPPING_SIM_WORLD_H_
