#include "wavog_mapping/sim/world_file.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>

namespace wavog {
namespace sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Reads one YAML node, naming its place ("objects[3].box") in every error.
class Reader {
 public:
  explicit Reader(std::string origin) : origin_(std::move(origin)) {}

  [[noreturn]] void fail(const std::string& where, const std::string& why) const {
    throw WorldFileError(origin_ + ": " + where + ": " + why);
  }

  void checkKeys(const YAML::Node& node, const std::string& where,
                 const std::set<std::string>& allowed) const {
    if (!node.IsMap()) fail(where, "expected a mapping");
    for (const auto& kv : node) {
      const std::string key = kv.first.as<std::string>();
      if (!allowed.count(key)) {
        std::string list;
        for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
        fail(where, "unknown key '" + key + "' (known: " + list + ")");
      }
    }
  }

  double number(const YAML::Node& node, const std::string& where) const {
    try {
      const double v = node.as<double>();
      if (!std::isfinite(v)) fail(where, "must be finite");
      return v;
    } catch (const YAML::Exception&) {
      fail(where, "expected a number");
    }
  }

  double number(const YAML::Node& map, const std::string& key, const std::string& where,
                double fallback) const {
    return map[key] ? number(map[key], where + "." + key) : fallback;
  }

  std::string text(const YAML::Node& map, const std::string& key, const std::string& where,
                   const std::string& fallback) const {
    if (!map[key]) return fallback;
    try {
      return map[key].as<std::string>();
    } catch (const YAML::Exception&) {
      fail(where + "." + key, "expected a string");
    }
  }

  std::vector<double> numbers(const YAML::Node& node, const std::string& where,
                              std::size_t count) const {
    if (!node.IsSequence() || (count && node.size() != count)) {
      fail(where, "expected a list of " + (count ? std::to_string(count) + " " : "") + "numbers");
    }
    std::vector<double> out;
    for (std::size_t i = 0; i < node.size(); ++i) {
      out.push_back(number(node[i], where + "[" + std::to_string(i) + "]"));
    }
    return out;
  }

  Polygon polygon(const YAML::Node& node, const std::string& where) const {
    if (!node.IsSequence()) fail(where, "expected a list of [x, y] points");
    Polygon poly;
    for (std::size_t i = 0; i < node.size(); ++i) {
      const std::vector<double> p = numbers(node[i], where + "[" + std::to_string(i) + "]", 2);
      poly.emplace_back(p[0], p[1]);
    }
    if (poly.size() < 3) fail(where, "a polygon needs at least 3 points");
    return poly;
  }

  // shape from one of polygon / box / circle.
  Polygon shape(const YAML::Node& map, const std::string& where) const {
    const int given = (map["polygon"] ? 1 : 0) + (map["box"] ? 1 : 0) + (map["circle"] ? 1 : 0);
    if (given != 1) fail(where, "give exactly one of polygon, box, circle");
    if (map["polygon"]) return polygon(map["polygon"], where + ".polygon");
    if (map["box"]) {
      const std::vector<double> b = numbers(map["box"], where + ".box", 2);
      if (!(b[0] > 0 && b[1] > 0)) fail(where + ".box", "length and width must be > 0");
      return makeBox(b[0], b[1]);
    }
    const std::vector<double> c = numbers(map["circle"], where + ".circle", 2);
    if (!(c[0] > 0 && c[1] >= 3)) fail(where + ".circle", "need radius > 0 and sides >= 3");
    return makeRegular(static_cast<int>(c[1]), c[0]);
  }

  // trajectory: [[t, x, y, theta_deg], ...] or route: {speed, start, corner_radius, points}.
  Trajectory trajectory(const YAML::Node& map, const std::string& where) const {
    if (map["trajectory"] && map["route"]) fail(where, "give trajectory or route, not both");
    Trajectory traj;
    if (map["trajectory"]) {
      const YAML::Node& list = map["trajectory"];
      if (!list.IsSequence()) fail(where + ".trajectory", "expected [[t, x, y, theta_deg], ...]");
      for (std::size_t i = 0; i < list.size(); ++i) {
        const std::vector<double> w =
            numbers(list[i], where + ".trajectory[" + std::to_string(i) + "]", 4);
        traj.waypoints.push_back(Waypoint{w[0], Pose2{w[1], w[2], w[3] * kDeg}});
      }
    } else if (map["route"]) {
      const YAML::Node& r = map["route"];
      const std::string rw = where + ".route";
      checkKeys(r, rw, {"speed", "start", "corner_radius", "points"});
      const double speed = number(r, "speed", rw, 0.0);
      if (!(speed > 0)) fail(rw + ".speed", "must be > 0 m/s");
      const Polygon pts = r["points"] ? polygonPoints(r["points"], rw + ".points") : Polygon();
      if (pts.size() < 2) fail(rw + ".points", "need at least 2 points");
      traj = Trajectory::fromRoute(pts, speed, number(r, "start", rw, 0.0),
                                   number(r, "corner_radius", rw, 0.0));
    }
    return traj;
  }

  Polygon polygonPoints(const YAML::Node& node, const std::string& where) const {
    if (!node.IsSequence()) fail(where, "expected a list of [x, y] points");
    Polygon pts;
    for (std::size_t i = 0; i < node.size(); ++i) {
      const std::vector<double> p = numbers(node[i], where + "[" + std::to_string(i) + "]", 2);
      pts.emplace_back(p[0], p[1]);
    }
    return pts;
  }

  LaserParams laser(const YAML::Node& map, const std::string& where, double length,
                    double width) const {
    checkKeys(map, where,
              {"corner", "name", "frame_id", "topic", "x", "y", "yaw_deg", "beams", "fov_deg",
               "range_min", "range_max", "rate_hz", "phase_s", "noise_sigma", "dropout_prob"});
    LaserParams l;
    if (map["corner"]) {
      const std::string corner = text(map, "corner", where, "");
      const char* const names[4] = {"front_left", "front_right", "rear_left", "rear_right"};
      int index = -1;
      for (int i = 0; i < 4; ++i) {
        if (corner == names[i]) index = i;
      }
      if (index < 0)
        fail(where + ".corner", "one of front_left, front_right, rear_left, rear_right");
      if (!(length > 0 && width > 0)) fail(where + ".corner", "needs the vehicle's box");
      l = cornerLaser(index, length, width);
    }
    l.name = text(map, "name", where, l.name);
    l.frame_id = text(map, "frame_id", where, map["name"] ? "laser_" + l.name : l.frame_id);
    l.topic = text(map, "topic", where, map["name"] ? "scan_" + l.name : l.topic);
    l.mount.x = number(map, "x", where, l.mount.x);
    l.mount.y = number(map, "y", where, l.mount.y);
    l.mount.theta = number(map, "yaw_deg", where, l.mount.theta / kDeg) * kDeg;
    const double beams = number(map, "beams", where, l.beams);
    if (beams != std::floor(beams) || beams < 2 || beams > 100000) {
      fail(where + ".beams", "must be an integer in [2, 100000]");
    }
    l.beams = static_cast<int>(beams);
    l.fov = number(map, "fov_deg", where, l.fov / kDeg) * kDeg;
    l.range_min = number(map, "range_min", where, l.range_min);
    l.range_max = number(map, "range_max", where, l.range_max);
    l.rate_hz = number(map, "rate_hz", where, l.rate_hz);
    l.phase_s = number(map, "phase_s", where, l.phase_s);
    l.noise_sigma = number(map, "noise_sigma", where, l.noise_sigma);
    l.dropout_prob = number(map, "dropout_prob", where, l.dropout_prob);
    return l;
  }

  World world(const YAML::Node& root) const {
    checkKeys(root, "top level", {"name", "duration", "region", "objects", "vehicle"});
    World w;
    w.name = text(root, "name", "top level", w.name);
    w.duration = number(root, "duration", "top level", w.duration);
    if (root["region"]) {
      const std::vector<double> r = numbers(root["region"], "region", 4);
      w.region_min = Vec2(r[0], r[1]);
      w.region_max = Vec2(r[2], r[3]);
    }
    if (root["objects"]) {
      const YAML::Node& objs = root["objects"];
      if (!objs.IsSequence()) fail("objects", "expected a list");
      for (std::size_t i = 0; i < objs.size(); ++i) {
        const std::string where = "objects[" + std::to_string(i) + "]";
        const YAML::Node& o = objs[i];
        checkKeys(o, where,
                  {"name", "kind", "role", "polygon", "box", "circle", "trajectory", "route",
                   "appear", "disappear"});
        WorldObject obj;
        obj.name = text(o, "name", where, "object_" + std::to_string(i));
        if (!fromString(text(o, "kind", where, "obstacle"), &obj.kind)) {
          fail(where + ".kind", "one of wall, car, pedestrian, obstacle");
        }
        if (!fromString(text(o, "role", where, "static"), &obj.role)) {
          fail(where + ".role", "one of static, moving, departing, arriving");
        }
        obj.shape = shape(o, where);
        obj.trajectory = trajectory(o, where);
        obj.appear_time = number(o, "appear", where, obj.appear_time);
        obj.disappear_time = number(o, "disappear", where, obj.disappear_time);
        w.objects.push_back(std::move(obj));
      }
    }
    if (!root["vehicle"]) fail("top level", "missing 'vehicle'");
    const YAML::Node& v = root["vehicle"];
    checkKeys(v, "vehicle", {"box", "polygon", "trajectory", "route", "lasers"});
    double length = 0.0, width = 0.0;
    if (v["box"]) {
      const std::vector<double> b = numbers(v["box"], "vehicle.box", 2);
      length = b[0];
      width = b[1];
      w.vehicle.footprint = makeBox(length, width);
    } else if (v["polygon"]) {
      w.vehicle.footprint = polygon(v["polygon"], "vehicle.polygon");
    }
    w.vehicle.path = trajectory(v, "vehicle");
    if (!v["lasers"] || !v["lasers"].IsSequence()) fail("vehicle", "'lasers' must be a list");
    for (std::size_t i = 0; i < v["lasers"].size(); ++i) {
      w.vehicle.lasers.push_back(
          laser(v["lasers"][i], "vehicle.lasers[" + std::to_string(i) + "]", length, width));
    }
    const std::vector<std::string> errors = w.validate();
    if (!errors.empty()) {
      std::string all;
      for (const std::string& e : errors) all += "\n  " + e;
      throw WorldFileError(origin_ + ": invalid world:" + all);
    }
    return w;
  }

 private:
  std::string origin_;
};

void writePoints(std::ostream& out, const Polygon& poly) {
  out << "[";
  for (std::size_t i = 0; i < poly.size(); ++i) {
    out << (i ? ", " : "") << "[" << poly[i].x() << ", " << poly[i].y() << "]";
  }
  out << "]";
}

void writeTrajectory(std::ostream& out, const Trajectory& traj) {
  out << "[";
  for (std::size_t i = 0; i < traj.waypoints.size(); ++i) {
    const Waypoint& w = traj.waypoints[i];
    out << (i ? ", " : "") << "[" << w.t << ", " << w.pose.x << ", " << w.pose.y << ", "
        << w.pose.theta / kDeg << "]";
  }
  out << "]";
}

}  // namespace

World parseWorld(const std::string& text, const std::string& origin) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw WorldFileError(origin + ": syntax error: " + e.what());
  }
  return Reader(origin).world(root);
}

World loadWorld(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw WorldFileError(path + ": cannot open");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parseWorld(buffer.str(), path);
}

std::string worldToYaml(const World& world) {
  std::ostringstream out;
  out << std::setprecision(17);
  out << "# World of wavog_simulate (see include/wavog_mapping/sim/world_file.h). Angles in deg.\n";
  out << "name: " << world.name << "\n";
  out << "duration: " << world.duration << "\n";
  out << "region: [" << world.region_min.x() << ", " << world.region_min.y() << ", "
      << world.region_max.x() << ", " << world.region_max.y() << "]\n";
  out << "objects:\n";
  for (const WorldObject& o : world.objects) {
    out << "  - {name: " << o.name << ", kind: " << toString(o.kind)
        << ", role: " << toString(o.role) << ",\n     polygon: ";
    writePoints(out, o.shape);
    if (!o.trajectory.empty()) {
      out << ",\n     trajectory: ";
      writeTrajectory(out, o.trajectory);
    }
    if (std::isfinite(o.appear_time)) out << ", appear: " << o.appear_time;
    if (std::isfinite(o.disappear_time)) out << ", disappear: " << o.disappear_time;
    out << "}\n";
  }
  out << "vehicle:\n  polygon: ";
  writePoints(out, world.vehicle.footprint);
  out << "\n  trajectory: ";
  writeTrajectory(out, world.vehicle.path);
  out << "\n  lasers:\n";
  for (const LaserParams& l : world.vehicle.lasers) {
    out << "    - {name: " << l.name << ", frame_id: " << l.frame_id << ", topic: " << l.topic
        << ", x: " << l.mount.x << ", y: " << l.mount.y << ", yaw_deg: " << l.mount.theta / kDeg
        << ",\n       beams: " << l.beams << ", fov_deg: " << l.fov / kDeg
        << ", range_min: " << l.range_min << ", range_max: " << l.range_max
        << ", rate_hz: " << l.rate_hz << ", phase_s: " << l.phase_s
        << ", noise_sigma: " << l.noise_sigma << ", dropout_prob: " << l.dropout_prob << "}\n";
  }
  return out.str();
}

}  // namespace sim
}  // namespace wavog
