#include "wavog_mapping/sim/world.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace wavog {
namespace sim {
namespace {

using Points = std::vector<Vec2, Eigen::aligned_allocator<Vec2>>;

// Passenger car and truck sizes of the default world (m).
constexpr double kCarLength = 4.4;
constexpr double kCarWidth = 1.8;
constexpr double kTruckLength = 8.0;
constexpr double kTruckWidth = 2.5;
constexpr double kWallThickness = 0.4;

Waypoint wp(double t, double x, double y, double theta) { return Waypoint{t, Pose2{x, y, theta}}; }

WorldObject wall(const std::string& name, double x0, double y0, double x1, double y1) {
  WorldObject o;
  o.name = name;
  o.kind = ObjectKind::kWall;
  o.shape = makeRect(x0, y0, x1, y1);
  return o;
}

WorldObject parkedCar(const std::string& name, double x, double y, double theta) {
  WorldObject o;
  o.name = name;
  o.kind = ObjectKind::kCar;
  o.shape = makeBox(kCarLength, kCarWidth);
  o.trajectory.waypoints = {wp(0.0, x, y, theta)};
  return o;
}

}  // namespace

Pose2 Trajectory::at(double t) const {
  if (waypoints.empty()) return Pose2{};
  if (t <= waypoints.front().t) return waypoints.front().pose;
  if (t >= waypoints.back().t) return waypoints.back().pose;
  const auto it = std::upper_bound(waypoints.begin(), waypoints.end(), t,
                                   [](double v, const Waypoint& w) { return v < w.t; });
  const Waypoint& b = *it;
  const Waypoint& a = *(it - 1);
  const double f = (t - a.t) / (b.t - a.t);
  return Pose2{a.pose.x + f * (b.pose.x - a.pose.x), a.pose.y + f * (b.pose.y - a.pose.y),
               wrapAngle(a.pose.theta + f * wrapAngle(b.pose.theta - a.pose.theta))};
}

Trajectory Trajectory::fromRoute(const Points& points, double speed, double t0,
                                 double corner_radius) {
  // Round each interior corner with a quadratic Bezier between the points corner_radius before
  // and after it (never more than half of either adjacent segment), sampled finely enough that
  // the heading turns by a few degrees per sample.
  constexpr int kArcSamples = 8;
  Points path;
  if (!points.empty()) path.push_back(points.front());
  for (std::size_t i = 1; i + 1 < points.size(); ++i) {
    const Vec2 in = points[i] - points[i - 1];
    const Vec2 out = points[i + 1] - points[i];
    const double r = std::min({corner_radius, in.norm() / 2, out.norm() / 2});
    if (r <= 0.0) {
      path.push_back(points[i]);
      continue;
    }
    const Vec2 p0 = points[i] - r * in.normalized();
    const Vec2 p2 = points[i] + r * out.normalized();
    for (int k = 0; k <= kArcSamples; ++k) {
      const double u = static_cast<double>(k) / kArcSamples;
      path.push_back((1 - u) * (1 - u) * p0 + 2 * u * (1 - u) * points[i] + u * u * p2);
    }
  }
  if (points.size() > 1) path.push_back(points.back());

  Trajectory traj;
  double t = t0;
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (i > 0) {
      const double len = (path[i] - path[i - 1]).norm();
      if (len < 1e-9) continue;
      t += len / speed;
    }
    // Heading along the outgoing segment (incoming for the last point): exact on straights.
    const Vec2 d = i + 1 < path.size() ? path[i + 1] - path[i] : path[i] - path[i - 1];
    traj.waypoints.push_back(wp(t, path[i].x(), path[i].y(), std::atan2(d.y(), d.x())));
  }
  return traj;
}

const char* toString(ObjectKind kind) {
  switch (kind) {
    case ObjectKind::kWall:
      return "wall";
    case ObjectKind::kCar:
      return "car";
    case ObjectKind::kPedestrian:
      return "pedestrian";
    case ObjectKind::kObstacle:
      return "obstacle";
  }
  return "?";
}

const char* toString(ObjectRole role) {
  switch (role) {
    case ObjectRole::kStatic:
      return "static";
    case ObjectRole::kMoving:
      return "moving";
    case ObjectRole::kDeparting:
      return "departing";
    case ObjectRole::kArriving:
      return "arriving";
  }
  return "?";
}

bool fromString(const std::string& name, ObjectKind* kind) {
  for (ObjectKind k :
       {ObjectKind::kWall, ObjectKind::kCar, ObjectKind::kPedestrian, ObjectKind::kObstacle}) {
    if (name == toString(k)) {
      *kind = k;
      return true;
    }
  }
  return false;
}

bool fromString(const std::string& name, ObjectRole* role) {
  for (ObjectRole r :
       {ObjectRole::kStatic, ObjectRole::kMoving, ObjectRole::kDeparting, ObjectRole::kArriving}) {
    if (name == toString(r)) {
      *role = r;
      return true;
    }
  }
  return false;
}

Polygon WorldObject::polygonAt(double t) const {
  return trajectory.empty() ? shape : transformed(shape, trajectory.at(t));
}

std::vector<Polygon> World::polygonsAt(double t, std::vector<int>* owners) const {
  std::vector<Polygon> polys;
  if (owners) owners->clear();
  for (std::size_t i = 0; i < objects.size(); ++i) {
    if (!objects[i].presentAt(t)) continue;
    polys.push_back(objects[i].polygonAt(t));
    if (owners) owners->push_back(static_cast<int>(i));
  }
  return polys;
}

std::vector<std::string> World::validate() const {
  std::vector<std::string> errors;
  auto fail = [&errors](const std::string& what) { errors.push_back(what); };
  if (!(duration > 0.0)) fail("duration must be > 0 s");
  if (!(region_min.x() < region_max.x() && region_min.y() < region_max.y())) {
    fail("region: min must be below max on both axes");
  }
  auto check_traj = [&fail](const std::string& who, const Trajectory& traj) {
    for (std::size_t i = 1; i < traj.waypoints.size(); ++i) {
      if (!(traj.waypoints[i].t > traj.waypoints[i - 1].t)) {
        fail(who + ": trajectory times must increase strictly");
        return;
      }
    }
  };
  for (const WorldObject& o : objects) {
    if (o.shape.size() < 3) fail("object '" + o.name + "': a polygon needs >= 3 vertices");
    if (!(o.appear_time < o.disappear_time)) {
      fail("object '" + o.name + "': appear must be before disappear");
    }
    check_traj("object '" + o.name + "'", o.trajectory);
  }
  if (vehicle.path.empty()) fail("vehicle: path is empty");
  check_traj("vehicle", vehicle.path);
  if (vehicle.lasers.empty()) fail("vehicle: no laser");
  for (const LaserParams& l : vehicle.lasers) {
    const std::string who = "laser '" + l.name + "': ";
    if (l.beams < 2) fail(who + "beams must be >= 2");
    if (!(l.fov > 0.0 && l.fov <= 2 * M_PI)) fail(who + "fov must be in (0, 2 pi]");
    if (!(l.range_min >= 0.0 && l.range_min < l.range_max)) {
      fail(who + "need 0 <= range_min < range_max");
    }
    if (!(l.rate_hz > 0.0)) fail(who + "rate_hz must be > 0");
    if (!(l.noise_sigma >= 0.0)) fail(who + "noise_sigma must be >= 0");
    if (!(l.dropout_prob >= 0.0 && l.dropout_prob <= 1.0)) fail(who + "dropout in [0, 1]");
    if (l.frame_id.empty() || l.frame_id[0] == '/') fail(who + "frame_id empty or with '/'");
  }
  return errors;
}

LaserParams cornerLaser(int corner, double length, double width) {
  static const char* const kNames[4] = {"front_left", "front_right", "rear_left", "rear_right"};
  const double sx = corner < 2 ? 1.0 : -1.0;
  const double sy = corner % 2 == 0 ? 1.0 : -1.0;
  LaserParams l;
  l.name = kNames[corner];
  // Frames and topics as in config/lms291_x4.yaml.
  l.frame_id = "laser_" + l.name;
  l.topic = "scan_" + l.name;
  // Facing outwards along the corner's diagonal: 180 deg then sweeps both adjacent sides.
  l.mount = Pose2{sx * length / 2, sy * width / 2, std::atan2(sy, sx)};
  l.phase_s = corner / (4.0 * l.rate_hz);  // stagger the four lasers over one period
  return l;
}

World defaultWorld(double duration) {
  World w;
  w.name = "car_park";
  w.duration = duration;
  constexpr double kXMax = 70.0;
  constexpr double kYMax = 34.0;
  constexpr double kT = kWallThickness;
  w.region_min = Vec2(-2.0, -2.0);
  w.region_max = Vec2(kXMax + 2.0, kYMax + 2.0);

  // Enclosure, open on the west side at the two aisles (the car park's entrances).
  w.objects.push_back(wall("wall_south", -kT, -kT, kXMax + kT, 0.0));
  w.objects.push_back(wall("wall_north", -kT, kYMax, kXMax + kT, kYMax + kT));
  w.objects.push_back(wall("wall_east", kXMax, 0.0, kXMax + kT, kYMax));
  w.objects.push_back(wall("wall_west_1", -kT, 0.0, 0.0, 5.4));
  w.objects.push_back(wall("wall_west_2", -kT, 12.0, 0.0, 21.2));
  w.objects.push_back(wall("wall_west_3", -kT, 27.8, 0.0, kYMax));
  w.objects.push_back(wall("kiosk", 1.5, 28.5, 8.5, 33.0));
  for (double x : {11.2, 59.6}) {
    for (double y : {3.2, 16.7, 30.0}) {
      std::ostringstream name;
      name << "pillar_" << x << "_" << y;
      w.objects.push_back(wall(name.str(), x - 0.3, y - 0.3, x + 0.3, y + 0.3));
    }
  }

  // Four rows of 18 stalls 2.6 m apart; rows B and C back to back between the two aisles.
  // About 70 % of the stalls hold a car, in a fixed pattern; B4 leaves, D7 is where one arrives.
  const double row_y[4] = {3.2, 14.4, 19.0, 30.0};
  const char row_name[4] = {'A', 'B', 'C', 'D'};
  constexpr int kStalls = 18;
  auto stall_x = [](int k) { return 13.25 + 2.6 * k; };
  for (int r = 0; r < 4; ++r) {
    for (int k = 0; k < kStalls; ++k) {
      const bool departing = r == 1 && k == 4;
      const bool arrival_stall = r == 3 && k == 7;
      // A17 stays free so the truck's tail can swing over it at the east turn.
      const bool empty_stall = (k * 7 + r * 3) % 10 < 3 || (r == 0 && k == 17);
      if (arrival_stall || (empty_stall && !departing)) continue;
      std::ostringstream name;
      name << "car_" << row_name[r] << k;
      w.objects.push_back(parkedCar(name.str(), stall_x(k), row_y[r], M_PI / 2));
    }
  }

  // B4 backs out into aisle 1 at t = 10 s, once the truck has passed it, turns and drives out
  // through the west entrance; the truck's rear lasers watch its stall empty.
  for (WorldObject& o : w.objects) {
    if (o.name != "car_B4") continue;
    const double x = stall_x(4);
    o.role = ObjectRole::kDeparting;
    o.trajectory.waypoints = {wp(0.0, x, row_y[1], M_PI / 2), wp(10.0, x, row_y[1], M_PI / 2),
                              wp(13.0, x, 9.4, M_PI / 2), wp(15.0, x - 2.5, 10.6, M_PI),
                              wp(20.0, -6.0, 10.6, M_PI)};
    o.disappear_time = 20.0;
  }
  // A car enters through the west entrance of aisle 2 at t = 16 s and parks in stall D7.
  {
    WorldObject o;
    o.name = "car_arriving_D7";
    o.kind = ObjectKind::kCar;
    o.role = ObjectRole::kArriving;
    o.shape = makeBox(kCarLength, kCarWidth);
    const double x = stall_x(7);
    o.trajectory.waypoints = {wp(16.0, -6.0, 25.6, 0.0), wp(23.0, x - 2.5, 25.6, 0.0),
                              wp(25.0, x, 27.2, M_PI / 2), wp(27.0, x, row_y[3], M_PI / 2)};
    o.appear_time = 16.0;
    w.objects.push_back(o);
  }
  // A car crossing: down the east road, then west along aisle 1 and out.
  {
    WorldObject o;
    o.name = "car_crossing";
    o.kind = ObjectKind::kCar;
    o.role = ObjectRole::kMoving;
    o.shape = makeBox(kCarLength, kCarWidth);
    o.trajectory = Trajectory::fromRoute({Vec2(66.5, 31.0), Vec2(66.5, 10.8), Vec2(-6.0, 10.8)},
                                         5.0, 6.0, 3.0);
    o.appear_time = 6.0;
    o.disappear_time = o.trajectory.waypoints.back().t;
    w.objects.push_back(o);
  }
  // A pedestrian crossing aisle 1 in front of the truck, then walking along row A.
  {
    WorldObject o;
    o.name = "pedestrian";
    o.kind = ObjectKind::kPedestrian;
    o.role = ObjectRole::kMoving;
    o.shape = makeRegular(8, 0.3);
    o.trajectory.waypoints = {wp(0.0, 50.0, 11.8, -M_PI / 2), wp(6.0, 50.0, 11.8, -M_PI / 2),
                              wp(12.5, 50.0, 6.0, -M_PI / 2), wp(13.5, 49.5, 6.0, M_PI),
                              wp(20.0, 44.0, 6.0, M_PI)};
    w.objects.push_back(o);
  }

  // The truck: aisle 1 eastwards, up the east road, aisle 2 westwards, down the west side, again.
  w.vehicle.footprint = makeBox(kTruckLength, kTruckWidth);
  const Points loop = {Vec2(5.0, 7.8),   Vec2(64.0, 7.8), Vec2(64.0, 24.5),
                       Vec2(5.0, 24.5),  Vec2(5.0, 7.8),  Vec2(64.0, 7.8),
                       Vec2(64.0, 24.5), Vec2(5.0, 24.5), Vec2(5.0, 7.8)};
  w.vehicle.path = Trajectory::fromRoute(loop, 3.0, 0.0, 4.0);
  for (int c = 0; c < 4; ++c) w.vehicle.lasers.push_back(cornerLaser(c, kTruckLength, kTruckWidth));
  return w;
}

World fleetMember(const World& world, int k, int n) {
  if (n < 1 || k < 0 || k >= n) {
    throw std::invalid_argument("fleet member " + std::to_string(k) + " of " + std::to_string(n) +
                                ": need 0 <= k < n");
  }
  World w = world;
  auto& wps = w.vehicle.path.waypoints;
  if (k == 0 || wps.size() < 2) return w;
  const double lap = (wps.back().t - wps.front().t) / 2.0;
  const double shift = lap * static_cast<double>(k) / static_cast<double>(n);
  for (Waypoint& p : wps) p.t -= shift;
  return w;
}

World testWorld(double depart_time, double duration, double noise_sigma) {
  World w;
  w.name = "test_wall_and_car";
  w.duration = duration;
  w.region_min = Vec2(-1.0, -11.0);
  w.region_max = Vec2(11.0, 11.0);
  w.objects.push_back(wall("wall", 10.0, -10.0, 10.4, 10.0));
  WorldObject car = parkedCar("car", 5.0, 0.0, M_PI / 2);
  car.role = ObjectRole::kDeparting;
  car.disappear_time = depart_time;
  w.objects.push_back(car);
  w.vehicle.footprint = makeBox(1.0, 1.0);
  w.vehicle.path.waypoints = {wp(0.0, 0.0, 0.0, 0.0)};
  LaserParams l;
  l.name = "front";
  l.frame_id = "front_laser";
  l.topic = "front/scan";
  l.noise_sigma = noise_sigma;
  l.dropout_prob = 0.0;
  w.vehicle.lasers.push_back(l);
  return w;
}

}  // namespace sim
}  // namespace wavog
