// wavog_simulate: runs a simulated scenario (the built-in car park or a YAML/JSON world file) and
// writes a rosbag that the mapping node and wavog_offline consume unchanged: one
// sensor_msgs/LaserScan topic per laser, /tf (map -> base_link at every scan time) and a latched
// /tf_static (base_link -> each laser). Optionally writes the ground truth (the world file and
// rasterised occupancy at chosen times). Deterministic for a seed; needs no roscore.
#include <geometry_msgs/TransformStamped.h>
#include <ros/time.h>
#include <rosbag/bag.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>
#include <ros/serialization.h>
#include <wavog_mapping/PlacedScan.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "fleet/range_codec.h"
#include "tool_support.h"
#include "wavog_mapping/io/image_io.h"
#include "wavog_mapping/sim/ground_truth.h"
#include "wavog_mapping/sim/laser_sim.h"
#include "wavog_mapping/sim/pose_noise.h"
#include "wavog_mapping/sim/world.h"
#include "wavog_mapping/sim/world_file.h"

namespace {

using wavog::sim::GridWindow;
using wavog::sim::LaserParams;
using wavog::sim::SimScan;
using wavog::sim::World;

// Bag time of scenario time 0: a plausible epoch, so stamps are never zero (tf treats 0 as
// "latest") and tools that print dates show something sensible.
constexpr double kEpoch = 1.7e9;

struct Options {
  std::string world_file;  // empty: the built-in car park
  std::string bag = "scenario.bag";
  std::uint64_t seed = 1;
  double duration = -1.0;     // < 0: the world's
  double noise_sigma = -1.0;  // < 0: each laser's
  double dropout = -1.0;      // < 0: each laser's
  std::string map_frame = "map";
  std::string base_frame = "base_link";
  std::string truth_dir;  // empty: no ground truth written
  double truth_resolution = 0.1;
  double truth_every = 10.0;
  std::string write_world;  // write the world as YAML here
  // Error of the /tf poses (the lasers measure from the true pose).
  wavog::sim::PoseNoiseParams pose_noise;  // its seed: poseNoise()
  long pose_seed = -1;                     // < 0: --seed
  // A fleet: vehicle k (1..vehicles) in namespace <prefix>k (topics /<prefix>k/..., frames
  // <prefix>k/...), on the route started k-1 / vehicles of a lap further (fleetMember).
  long vehicles = 1;
  std::string vehicle_prefix = "v";
  bool placed_scans = false;  // write each vehicle's PlacedScan stream instead of scans and /tf
  std::string placed_format = "uint16";  // its ranges: uint16 (version 2) or float32 (version 1)
};

/// An angle option given in degrees, kept in radians (read whole, as addNumber).
void addDegrees(CLI::App* app, const std::string& name, double* radians, const std::string& help) {
  std::ostringstream shown;
  shown << *radians * 180.0 / M_PI;
  app->add_option_function<std::string>(
         name,
         [name, radians](const std::string& v) {
           *radians = wavog_tools::parseNumber(name, v.c_str()) * M_PI / 180.0;
         },
         help)
      ->type_name("NUM")
      ->default_str(shown.str());
}

/// The /tf pose error options (the lasers always measure from the true pose).
void addPoseNoiseOptions(CLI::App* app, Options* o) {
  wavog_tools::addNumber(app, "--pose-sigma-xy", &o->pose_noise.sigma_xy_m,
                         "per-scan Gaussian error of the /tf position, x and y (m)");
  addDegrees(app, "--pose-sigma-yaw-deg", &o->pose_noise.sigma_yaw_rad,
             "per-scan Gaussian error of the /tf heading (deg)");
  wavog_tools::addNumber(app, "--pose-drift-x", &o->pose_noise.drift_x_m_per_s,
                         "slow linear drift of the /tf position along x (m/s)");
  wavog_tools::addNumber(app, "--pose-drift-y", &o->pose_noise.drift_y_m_per_s,
                         "slow linear drift of the /tf position along y (m/s)");
  addDegrees(app, "--pose-drift-yaw-deg", &o->pose_noise.drift_yaw_rad_per_s,
             "slow linear drift of the /tf heading (deg/s)");
  wavog_tools::addInteger(app, "--pose-seed", &o->pose_seed, 0,
                          "seed of the pose errors (default: --seed)")
      ->default_str("--seed");
}

/// The pose error of the /tf poses, its seed --pose-seed or else --seed.
wavog::sim::PoseNoiseParams poseNoise(const Options& o) {
  wavog::sim::PoseNoiseParams p = o.pose_noise;
  p.seed = o.pose_seed >= 0 ? static_cast<std::uint64_t>(o.pose_seed) : o.seed;
  return p;
}

/// What --help says first.
constexpr const char* kDescription =
    "Simulates a vehicle with planar lasers (default: the car park with four LMS-291) and writes "
    "a rosbag: one LaserScan topic per laser, /tf (map -> base_link), /tf_static.";

/// The command line of wavog_simulate (its --help is generated from these).
void addOptions(CLI::App* app, Options* o) {
  app->add_option("--world", o->world_file, "YAML/JSON world (default: the built-in car park)");
  app->add_option("--out", o->bag, "output bag")->capture_default_str();
  wavog_tools::addInteger(app, "--seed", &o->seed, 0, "noise seed; same seed, same bag");
  wavog_tools::addNumber(app, "--duration", &o->duration,
                         "simulated seconds (< 0: the world's, 60 for the car park)");
  wavog_tools::addNumber(app, "--noise", &o->noise_sigma,
                         "range noise standard deviation (m) for every laser (< 0: each laser's)");
  wavog_tools::addNumber(app, "--dropout", &o->dropout,
                         "NaN dropout probability per beam for every laser (< 0: each laser's)");
  app->add_option("--map-frame", o->map_frame, "fixed frame of /tf")->capture_default_str();
  app->add_option("--base-frame", o->base_frame, "vehicle frame")->capture_default_str();
  app->add_option("--truth-dir", o->truth_dir,
                  "write ground truth there: world.yaml, truth_<t>s.png/.pgm/.yaml");
  wavog_tools::addNumber(app, "--truth-resolution", &o->truth_resolution,
                         "ground-truth cell size (m)");
  wavog_tools::addNumber(app, "--truth-every", &o->truth_every, "ground-truth snapshot period (s)");
  app->add_option("--write-world", o->write_world,
                  "write the world as YAML (e.g. to edit the default) and go on");
  wavog_tools::addInteger(app, "--vehicles", &o->vehicles, 1,
                          "vehicles of a fleet, each with the world's lasers, on the route spread "
                          "over a lap; > 1: topics /<prefix>k/..., frames <prefix>k/...");
  app->add_option("--vehicle-prefix", o->vehicle_prefix, "namespace prefix of the fleet's vehicles")
      ->capture_default_str();
  app->add_flag("--placed-scans", o->placed_scans,
                "write each vehicle's stream of placed scans (/<ns>/fleet_scans, PlacedScan, at "
                "the true sensor pose, as a mapper streams them) instead of its scans and /tf: "
                "a fleet bag for wavog_fleet (make fleet-bench)");
  app->add_option("--placed-format", o->placed_format,
                  "the placed scans' ranges, as a mapper's fleet_stream_format: uint16 (16-bit "
                  "codes, PlacedScan version 2, for a map without max_range) or float32 "
                  "(version 1)")
      ->check(CLI::IsMember({"uint16", "float32"}))
      ->capture_default_str();
  addPoseNoiseOptions(app, o);
}

void validate(const Options& o) {
  if (!(o.truth_resolution > 0.0)) throw std::invalid_argument("--truth-resolution must be > 0");
  if (!(o.truth_every > 0.0)) throw std::invalid_argument("--truth-every must be > 0");
  if (o.vehicles < 1 || o.vehicles > 64) throw std::invalid_argument("--vehicles must be in [1, 64]");
  if (o.vehicles > 1 && o.vehicle_prefix.find_first_of("/ ") != std::string::npos) {
    throw std::invalid_argument("--vehicle-prefix must be a plain name (no '/' or space)");
  }
  for (const std::string& e : poseNoise(o).validate()) throw std::invalid_argument(e);
}

geometry_msgs::TransformStamped transformMsg(const std::string& parent, const std::string& child,
                                             const wavog::Pose2& pose, const ros::Time& stamp) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = stamp;
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform.translation.x = pose.x;
  t.transform.translation.y = pose.y;
  t.transform.translation.z = 0.0;
  t.transform.rotation.z = std::sin(pose.theta / 2);
  t.transform.rotation.w = std::cos(pose.theta / 2);
  return t;
}

sensor_msgs::LaserScan scanMsg(const SimScan& scan, const LaserParams& laser,
                               const ros::Time& stamp) {
  sensor_msgs::LaserScan m;
  m.header.stamp = stamp;
  m.header.frame_id = laser.frame_id;
  m.angle_min = static_cast<float>(laser.angleMin());
  m.angle_increment = static_cast<float>(laser.angleIncrement());
  m.angle_max = static_cast<float>(laser.angleMin() + laser.angleIncrement() * (laser.beams - 1));
  // The simulated sweep is instantaneous: every beam at the scan's pose.
  m.time_increment = 0.0f;
  m.scan_time = static_cast<float>(1.0 / laser.rate_hz);
  m.range_min = static_cast<float>(laser.range_min);
  m.range_max = static_cast<float>(laser.range_max);
  m.ranges = scan.ranges;
  return m;
}

std::string absoluteTopic(const std::string& topic) {
  return topic.empty() || topic[0] == '/' ? topic : "/" + topic;
}

void writeTruth(const World& world, const Options& o) {
  std::filesystem::create_directories(o.truth_dir);
  std::ofstream(std::filesystem::path(o.truth_dir) / "world.yaml")
      << wavog::sim::worldToYaml(world);
  const GridWindow window =
      GridWindow::covering(world.region_min, world.region_max, o.truth_resolution);
  for (int k = 0; k * o.truth_every < world.duration + 1e-9; ++k) {
    const double t = k * o.truth_every;
    const std::vector<std::uint8_t> occ = wavog::sim::occupancyAt(world, t, window);
    // As a raster, so the image writers put north up and the map_server YAML gets the origin.
    wavog::Raster raster;
    raster.cell_size = o.truth_resolution;
    raster.box = wavog::CellBox{window.min_x, window.min_y, window.min_x + window.width,
                                window.min_y + window.height};
    raster.log_odds.resize(occ.size());
    raster.known.assign(occ.size(), 1);
    for (std::size_t i = 0; i < occ.size(); ++i) raster.log_odds[i] = occ[i] ? 20.0f : -20.0f;
    std::ostringstream base;
    base << (std::filesystem::path(o.truth_dir) / "truth_").string() << std::fixed
         << std::setprecision(1) << std::setw(6) << std::setfill('0') << t << "s";
    wavog::writePng(base.str() + ".png", wavog::renderGrey(raster));
    wavog::writeMapServerMap(base.str(), raster);
  }
}

int run(const Options& o) {
  validate(o);
  World world =
      o.world_file.empty() ? wavog::sim::defaultWorld() : wavog::sim::loadWorld(o.world_file);
  if (o.duration > 0.0) world.duration = o.duration;
  for (LaserParams& l : world.vehicle.lasers) {
    if (o.noise_sigma >= 0.0) l.noise_sigma = o.noise_sigma;
    if (o.dropout >= 0.0) l.dropout_prob = o.dropout;
  }
  if (!o.write_world.empty()) std::ofstream(o.write_world) << wavog::sim::worldToYaml(world);

  rosbag::Bag bag(o.bag, rosbag::bagmode::Write);
  const ros::Time t0(kEpoch);
  // One vehicle: names as before; a fleet: each vehicle under its namespace.
  std::vector<World> worlds;
  std::vector<std::string> names;
  for (long k = 0; k < o.vehicles; ++k) {
    worlds.push_back(wavog::sim::fleetMember(world, static_cast<int>(k), static_cast<int>(o.vehicles)));
    names.push_back(o.vehicles > 1 ? o.vehicle_prefix + std::to_string(k + 1) : "");
  }
  auto frame = [](const std::string& ns, const std::string& f) { return ns.empty() ? f : ns + "/" + f; };
  auto topic = [](const std::string& ns, const std::string& t) {
    return ns.empty() ? absoluteTopic(t) : "/" + ns + absoluteTopic(t);
  };
  tf2_msgs::TFMessage statics;
  for (std::size_t k = 0; k < worlds.size(); ++k) {
    for (const LaserParams& l : worlds[k].vehicle.lasers) {
      statics.transforms.push_back(
          transformMsg(frame(names[k], o.base_frame), frame(names[k], l.frame_id), l.mount, t0));
    }
  }
  // Latched, so that `rosbag play` re-latches it. A custom connection header replaces rosbag's
  // own, so it carries the type fields as well.
  auto latched = boost::make_shared<ros::M_string>();
  (*latched)["type"] = ros::message_traits::datatype<tf2_msgs::TFMessage>();
  (*latched)["md5sum"] = ros::message_traits::md5sum<tf2_msgs::TFMessage>();
  (*latched)["message_definition"] = ros::message_traits::definition<tf2_msgs::TFMessage>();
  (*latched)["latching"] = "1";
  (*latched)["callerid"] = "/wavog_simulate";
  bag.write("/tf_static", t0, statics, latched);

  const wavog::sim::PoseNoiseParams noise = poseNoise(o);
  std::size_t done = 0, tf_count = 0;
  std::uint64_t placed_bytes = 0;  // the placed scans serialised
  std::ostringstream summary;
  for (std::size_t k = 0; k < worlds.size(); ++k) {
    const World& w = worlds[k];
    const std::string base = frame(names[k], o.base_frame);
    const std::string map_frame = o.map_frame;
    // Each vehicle its own noise (the same seed for one vehicle, as before).
    wavog::sim::ScanSimulator sim(w, o.seed + k);
    std::vector<std::size_t> per_laser(w.vehicle.lasers.size(), 0);
    SimScan scan;
    std::uint64_t index = 0;
    wavog_fleet::RangeCodec codec;
    while (o.placed_scans && sim.next(&scan)) {
      const LaserParams& laser = w.vehicle.lasers[static_cast<std::size_t>(scan.laser)];
      wavog_mapping::PlacedScan m;
      m.version = wavog_mapping::PlacedScan::VERSION_FLOAT32;
      m.header.stamp = t0 + ros::Duration(scan.stamp);
      m.header.frame_id = map_frame;
      m.vehicle = names[k].empty() ? "/" : "/" + names[k];
      m.input = topic(names[k], laser.topic);
      m.index = index++;
      m.x = m.start_x = m.end_x = scan.sensor_pose.x;
      m.y = m.start_y = m.end_y = scan.sensor_pose.y;
      m.theta = m.start_theta = m.end_theta = scan.sensor_pose.theta;
      const wavog::ScanView view = scan.view(laser);
      m.angle_min = view.angle_min;
      m.angle_increment = view.angle_increment;
      m.range_min = view.range_min;
      m.range_max = view.range_max;
      m.period = 1.0 / laser.rate_hz;
      if (o.placed_format == "uint16" && codec.encode(view, wavog::MapParams{})) {
        m.version = wavog_mapping::PlacedScan::VERSION_UINT16;
        m.range_codes = codec.codes();
        m.range_step = codec.step();
      } else {
        m.ranges.assign(view.ranges, view.ranges + view.count);
      }
      placed_bytes += ros::serialization::serializationLength(m);
      bag.write(topic(names[k], "fleet_scans"), m.header.stamp, m);
      ++per_laser[static_cast<std::size_t>(scan.laser)];
      if (++done % 2000 == 0) std::cerr << "\rwavog_simulate: " << done << " placed scans";
    }
    if (o.placed_scans) {
      summary << (summary.tellp() > 0 ? ", " : " ") << index << " on "
              << topic(names[k], "fleet_scans");
      continue;
    }
    while (sim.next(&scan)) {
      const ros::Time stamp = t0 + ros::Duration(scan.stamp);
      tf2_msgs::TFMessage tf;
      const wavog::Pose2 told = wavog::sim::withPoseError(w, scan, noise).vehicle_pose;
      tf.transforms.push_back(transformMsg(map_frame, base, told, stamp));
      bag.write("/tf", stamp, tf);
      ++tf_count;
      const LaserParams& laser = w.vehicle.lasers[static_cast<std::size_t>(scan.laser)];
      LaserParams named = laser;
      named.frame_id = frame(names[k], laser.frame_id);
      bag.write(topic(names[k], laser.topic), stamp, scanMsg(scan, named, stamp));
      ++per_laser[static_cast<std::size_t>(scan.laser)];
      if (++done % 2000 == 0) std::cerr << "\rwavog_simulate: " << done << " scans";
    }
    // One more pose after the last scan, so a tf lookup at the last stamp never extrapolates.
    const ros::Time end = t0 + ros::Duration(w.duration);
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(transformMsg(map_frame, base, w.vehicle.path.at(w.duration), end));
    bag.write("/tf", end, tf);
    ++tf_count;
    for (std::size_t i = 0; i < per_laser.size(); ++i) {
      summary << (summary.tellp() > 0 ? ", " : " ") << per_laser[i] << " on "
              << topic(names[k], w.vehicle.lasers[i].topic);
    }
  }
  bag.close();

  std::cerr << "\rwavog_simulate: world '" << world.name << "', seed " << o.seed << ", "
            << world.duration << " s: wrote " << o.bag << " with" << summary.str() << ", "
            << tf_count << " on /tf (" << o.map_frame << " -> "
            << (o.vehicles > 1 ? o.vehicle_prefix + "<k>/" : "") << o.base_frame
            << "), 1 on /tf_static\n";
  if (o.placed_scans && done > 0) {
    std::cerr << "wavog_simulate: placed scans (" << o.placed_format << "): "
              << std::fixed << std::setprecision(1)
              << static_cast<double>(placed_bytes) / static_cast<double>(done)
              << " bytes per scan serialised\n";
  }
  if (!o.truth_dir.empty()) {
    writeTruth(world, o);
    std::cerr << "wavog_simulate: ground truth in " << o.truth_dir << "/\n";
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return wavog_tools::toolMain(argc, argv, "wavog_simulate", kDescription, addOptions, run);
}
