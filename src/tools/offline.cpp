// wavog_offline: maps a rosbag or a CARMEN log without a roscore, as fast as the core allows.
// Bags: /tf and /tf_static go into a tf2::BufferCore first, then every scan of the chosen topics is
// placed with lookupTransform(fixed frame, scan frame, stamp) and integrated through the node's
// conversions (scan checks, mirrored lasers, motion compensation over the sweep). CARMEN logs: the
// logged (corrected) laser poses are used as they are. The parameters come from the node's YAML
// through the one loader (wavog_ros::configFromXmlRpc). Writes per scale a PNG, a map_server PGM +
// YAML (the same of the reflection map, and an NDT picture, when kept), the native map,
// summary.json and optional snapshots.
#include "offline.h"

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2/buffer_core.h>
#include <tf2_msgs/TFMessage.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tool_support.h"
#include "wavog_mapping/core/motion_compensation.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/io/carmen_reader.h"
#include "wavog_mapping/io/image_io.h"
#include "wavog_mapping/io/map_files.h"
#include "wavog_mapping/io/ndt_image.h"
#include "wavog_mapping/ros/config.h"
#include "wavog_mapping/ros/conversions.h"
#include "wavog_mapping/ros/scan_placement.h"

namespace {

using namespace wavog_offline;  // NOLINT: the tool's own parts (offline.h)

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

std::vector<int> parseScales(const std::string& text) {
  std::vector<int> scales;
  for (const auto& item : wavog_tools::splitList(text)) {
    scales.push_back(static_cast<int>(wavog_tools::parseInteger("--scale", item.c_str(), 0)));
  }
  if (scales.empty()) throw std::invalid_argument("--scale needs at least one scale");
  return scales;
}

/// --laser-pose: six numbers separated by spaces (or commas), each read whole.
std::vector<double> parseLaserPose(const std::string& text) {
  std::string spaced = text;
  std::replace(spaced.begin(), spaced.end(), ',', ' ');
  std::istringstream in(spaced);
  std::vector<double> pose;
  for (std::string item; in >> item;) {
    pose.push_back(wavog_tools::parseNumber("--laser-pose", item.c_str()));
  }
  if (pose.size() != 6) {
    throw std::invalid_argument("--laser-pose: 6 numbers \"x y z yaw pitch roll\" (m, rad), not '" +
                                text + "'");
  }
  return pose;
}

/// What --help says first.
constexpr const char* kDescription =
    "Maps INPUT, a rosbag (LaserScan + /tf, /tf_static) or a CARMEN log (plain or .gz), without "
    "a roscore, and writes to the output folder: map_s<scale>.png (unknown in pale blue), "
    "map_s<scale>.pgm + .yaml (map_server), map.wavog (native map), summary.json (with "
    "--reflection also reflection_s<scale>.*, with --ndt ndt_s<scale>.png).";

/// The command line of wavog_offline (its --help is generated from these).
void addOptions(CLI::App* app, Options* o) {
  app->add_option("-o,--out", o->out, "output folder (created)")->capture_default_str();
  app->add_option("-c,--config", o->config,
                  "the node's YAML parameters (default: the compiled defaults)");
  app->add_option("--policy", o->policy,
                  "none|max|clamp|forget|clamp_lower|clamp_upper (over the YAML; the policy's "
                  "documented defaults apply to keys the YAML omits)");
  wavog_tools::addNumber(app, "--resolution", &o->resolution,
                         "finest cell size in m (over the YAML; 0: the YAML's)");
  app->add_option_function<std::string>(
      "--scale", [o](const std::string& v) { o->scales = parseScales(v); },
      "scales to write, e.g. 0,2,3 (default: 0 and publish_scales)");
  app->add_option("--aggregation", o->aggregation,
                  "mean|max: how a coarse cell summarises its cells (over the YAML)");
  wavog_tools::addInteger(app, "--max-scans", &o->max_scans, 0,
                          "integrate the first N scans only (0: all)");
  app->add_option_function<std::string>(
      "--topics", [o](const std::string& v) { o->topics = wavog_tools::splitList(v); },
      "bag scan topics, comma-separated (default: the YAML's inputs with --config, else every "
      "sensor_msgs/LaserScan topic of the bag)");
  app->add_option_function<std::string>(
      "--fixed-frame", [o](const std::string& v) { o->fixed_frame = wavog_tools::stripSlash(v); },
      "map frame (default: the YAML's map_frame); give the scan's own frame to map a bag "
      "without tf with the laser held fixed");
  app->add_option_function<std::string>(
      "--laser-parent", [o](const std::string& v) { o->laser_parent = wavog_tools::stripSlash(v); },
      "for a bag whose tf lacks the laser: hold each scan frame at --laser-pose in this frame "
      "(e.g. base_link), as the launch's laser_parent does");
  app->add_option_function<std::string>(
      "--laser-pose", [o](const std::string& v) { o->laser_pose = parseLaserPose(v); },
      "the scan frame in --laser-parent: \"x y z yaw pitch roll\" (m, rad; default 0 0 0 0 0 0)");
  wavog_tools::addNumber(app, "--snapshot-every", &o->snapshot_every,
                         "also write snapshots/t<seconds>_s<scale>.png every S s of log time "
                         "(0: none)");
  wavog_tools::addInteger(app, "--threads", &o->threads, 0,
                          "threads updating one scan's blocks (num_threads; 0: one per core; the "
                          "map is the same for every N)")
      ->default_str("the YAML's");
  app->add_flag("--reflection", o->reflection,
                "also keep the reflection probability map (reflection: true) and write "
                "reflection_s<scale>.png / .pgm / .yaml");
  app->add_flag("--ndt", o->ndt,
                "also keep normal-distribution cells (ndt: true) and write ndt_s<scale>.png: the "
                "map with each Gaussian's 2-sigma ellipse and its mean");
  app->add_flag_callback(
      "--no-progress", [o] { o->progress = false; }, "no progress bar");
  app->add_flag_callback(
      "--quiet",
      [o] {
        o->quiet = true;
        o->progress = false;
      },
      "only errors");
  app->add_option("input", o->input,
                  "a rosbag (LaserScan + /tf, /tf_static) or a CARMEN log (plain or .gz)")
      ->required();
}

std::string readText(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot read the configuration file");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// The node's loader, with the command-line overrides put into the parameter tree first, so that
/// they are validated (and the policy's defaults chosen) exactly as if the YAML held them.
wavog_ros::Config loadConfig(const Options& o, std::vector<std::string>* unknown) {
  XmlRpc::XmlRpcValue root;
  if (!o.config.empty()) {
    try {
      root = wavog_ros::yamlToXmlRpc(readText(o.config));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(o.config + ": " + e.what());
    }
  }
  if (!o.policy.empty()) root["policy"] = o.policy;
  if (o.resolution != 0.0) root["resolution"] = o.resolution;
  if (o.threads >= 0) root["num_threads"] = o.threads;
  if (o.reflection) root["reflection"] = true;
  if (!o.aggregation.empty()) root["scale_aggregation"] = o.aggregation;
  try {
    wavog_ros::Config config = wavog_ros::configFromXmlRpc(root, unknown);
    // Set here rather than in the tree: a flag needs no validation, and the YAML's `ndt` key is
    // read by the node's loader where it knows it.
    if (o.ndt) config.map.ndt = true;
    return config;
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument((o.config.empty() ? std::string("options") : o.config) + ": " +
                                e.what());
  }
}

/// Reflection probabilities as a raster of log-odds logit(p) (known where p is a number), so that
/// the occupancy map's pictures and map_server files show p as they show P(occupied).
wavog::Raster reflectionAsRaster(const wavog::ReflectionRaster& r) {
  wavog::Raster out;
  out.scale = r.scale;
  out.cell_size = r.cell_size;
  out.box = r.box;
  out.log_odds.resize(r.p.size());
  out.known.resize(r.p.size());
  for (std::size_t i = 0; i < r.p.size(); ++i) {
    const double p = std::clamp(static_cast<double>(r.p[i]), 1e-6, 1.0 - 1e-6);
    out.known[i] = std::isnan(r.p[i]) ? 0 : 1;
    out.log_odds[i] = std::isnan(r.p[i]) ? 0.0f : static_cast<float>(std::log(p / (1.0 - p)));
  }
  return out;
}

/// The NDT picture of one scale over its occupancy raster, and its entry of summary.json: the
/// number of Gaussians, their mean weight and the picture's pixels per cell.
Json writeNdt(const Options& o, const wavog::WaveletMap& map, const wavog::Raster& raster) {
  const wavog::NdtLayer layer = map.exportNdt(raster.scale, raster.box);
  const wavog::NdtRenderOptions options;
  const std::string png = wavog::scaleFileBase("ndt", raster.scale) + ".png";
  wavog::writePng((fs::path(o.out) / png).string(), wavog::renderNdt(raster, layer, options));
  double weight = 0.0;
  for (const wavog::NdtCell& c : layer.cells) weight += c.weight;
  return {
      {"png", png},
      {"gaussians", layer.cells.size()},
      {"mean_weight", layer.cells.empty() ? 0.0 : weight / static_cast<double>(layer.cells.size())},
      {"upscale", wavog::ndtUpscale(raster.box.width(), raster.box.height(), options)}};
}

/// Per scale: a PNG and a map_server map, cropped to the observed part (and the same of the
/// reflection map and the NDT picture, when kept); their entries of summary.json's "scales".
Json writeScales(const Options& o, const wavog_ros::Config& config, Session* session) {
  Json scales = Json::array();
  wavog::WaveletMap* map = &session->map();
  for (int scale : session->scales()) {
    wavog::CellBox box;
    if (!map->bounds(scale, &box)) break;
    const wavog::Raster raster =
        wavog::cropToKnown(map->exportScale(scale, box, config.ros.scale_aggregation));
    const std::string base = wavog::scaleFileBase("map", scale);  // as ~save_map names them
    wavog::writePng((fs::path(o.out) / (base + ".png")).string(), wavog::renderRgb(raster));
    // The map_server map carries the node's published values (map_values, the thresholds).
    wavog::RenderOptions image;
    image.values = config.ros.grid_values;
    wavog::writeMapServerMap((fs::path(o.out) / base).string(), raster, image);
    Json entry = {{"scale", scale},
                  {"cell_size_m", raster.cell_size},
                  {"width", raster.box.width()},
                  {"height", raster.box.height()},
                  {"origin", {raster.originX(), raster.originY()}},
                  {"png", base + ".png"},
                  {"pgm", base + ".pgm"},
                  {"yaml", base + ".yaml"}};
    if (config.map.reflection) {
      // Over the occupancy layer's box, drawn like it (p as the grey level, unknown pale blue).
      const wavog::Raster reflection = reflectionAsRaster(map->exportReflection(scale, raster.box));
      const std::string rbase = wavog::scaleFileBase("reflection", scale);
      wavog::writePng((fs::path(o.out) / (rbase + ".png")).string(), wavog::renderRgb(reflection));
      wavog::writeMapServerMap((fs::path(o.out) / rbase).string(), reflection);
      std::size_t reflecting = 0;  // cells with p >= 0.5
      for (std::size_t i = 0; i < reflection.known.size(); ++i) {
        reflecting += reflection.known[i] != 0 && reflection.log_odds[i] >= 0.0f;
      }
      entry["reflection"] = {{"png", rbase + ".png"},
                             {"pgm", rbase + ".pgm"},
                             {"yaml", rbase + ".yaml"},
                             {"cells_p_at_least_half", reflecting}};
    }
    if (config.map.ndt) entry["ndt"] = writeNdt(o, *map, raster);
    scales.push_back(entry);
  }
  return scales;
}

/// The first keys of summary.json: what was mapped, how, and what happened to the scans.
Json describeRun(const Options& o, const wavog_ros::Config& config, const InputInfo& info,
                 const Session& s) {
  Json j;
  j["input"] = o.input;
  j["input_type"] = info.type;
  j["config"] = o.config.empty() ? Json() : Json(o.config);
  j["policy"] = wavog::toString(config.map.policy.type);
  j["resolution_m"] = config.map.grid.resolution;
  j["aggregation"] = wavog_ros::toString(config.ros.scale_aggregation);
  j["fixed_frame"] = info.fixed_frame;
  j["laser_mount"] = info.laser_mount.empty() ? Json() : Json(info.laser_mount);
  j["topics"] = info.topics;
  j["scans_integrated"] = s.integrated();
  j["scans_dropped"] = s.droppedTotal();
  j["dropped_by_reason"] = Json::object();
  for (const auto& [reason, n] : s.dropped()) j["dropped_by_reason"][reason] = n;
  j["beams"] = {
      {"hit", s.beamsHit()}, {"no_return", s.beamsNoReturn()}, {"invalid", s.beamsInvalid()}};
  j["log_duration_s"] = s.logDuration();
  return j;
}

/// Bytes per observed cell of the map (0 for an empty map).
double bytesPerCell(const wavog::MapStats& stats) {
  return stats.observed_cells > 0
             ? static_cast<double>(stats.bytes) / static_cast<double>(stats.observed_cells)
             : 0.0;
}

/// summary.json: describeRun's keys, then timings, the map's size and the files written.
Json summaryOf(const Options& o, const wavog_ros::Config& config, const InputInfo& info,
               const Session& s, const wavog::MapStats& stats, double loop_s, double wall_s) {
  Json summary = describeRun(o, config, info, s);
  summary["wall_time_s"] = wall_s;
  summary["read_and_integrate_s"] = loop_s;
  summary["integrate_s"] = s.integrateSeconds();
  summary["scans_per_s"] = loop_s > 0 ? static_cast<double>(s.integrated()) / loop_s : 0.0;
  summary["integrate_scans_per_s"] =
      s.integrateSeconds() > 0 ? static_cast<double>(s.integrated()) / s.integrateSeconds() : 0.0;
  summary["motion_compensated"] = info.motion_compensated;
  summary["motion_fallbacks"] = info.motion_fallbacks;
  summary["nodes_visited_per_scan"] = s.integrated() > 0 ? static_cast<double>(s.nodesVisited()) /
                                                               static_cast<double>(s.integrated())
                                                         : 0.0;
  summary["map"] = {{"blocks", stats.blocks},
                    {"nodes", stats.nodes},
                    {"tiles", stats.tiles},
                    {"bytes", stats.bytes},
                    {"observed_cells", stats.observed_cells},
                    {"bytes_per_observed_cell", bytesPerCell(stats)}};
  if (config.map.ndt) {
    summary["map"]["ndt_cells"] = stats.ndt_cells;
    summary["map"]["ndt_bytes"] = stats.ndt_bytes;
  }
  summary["native_map"] = "map.wavog";
  summary["ndt"] = config.map.ndt;
  return summary;
}

/// The input readable, the configuration loaded (unknown keys warned about), the scales in
/// range, the output folder made.
wavog_ros::Config prepare(const Options& o) {
  if (!(o.snapshot_every >= 0.0)) throw std::invalid_argument("--snapshot-every must be >= 0");
  if (!(o.resolution >= 0.0)) {  // 0 keeps the YAML's; the loader checks the range of the rest
    std::ostringstream v;
    v << o.resolution;
    throw std::invalid_argument("--resolution (" + v.str() +
                                ") must be > 0 m, the finest cell size (0: the YAML's)");
  }
  if (!o.laser_pose.empty() && o.laser_parent.empty()) {
    throw std::invalid_argument("--laser-pose needs --laser-parent (the frame it is given in)");
  }
  if (fs::is_directory(o.input))
    throw std::runtime_error(o.input + ": cannot open: is a directory");
  if (!std::ifstream(o.input, std::ios::binary)) {
    throw std::runtime_error(o.input + ": cannot open: " + std::strerror(errno));
  }
  std::vector<std::string> unknown;
  wavog_ros::Config config = loadConfig(o, &unknown);
  if (!unknown.empty() && !o.quiet) {
    std::cerr << "wavog_offline: warning: unknown key(s) in " << o.config << " ignored:";
    for (const auto& k : unknown) std::cerr << " " << k;
    std::cerr << "\n";
  }
  if (!o.quiet) {
    for (const auto& w : config.map.warnings()) {
      std::cerr << "wavog_offline: warning: " << w << "\n";
    }
  }
  for (int s : o.scales) {
    if (s < 0 || s > config.map.grid.block_levels) {
      throw std::invalid_argument(
          "--scale " + std::to_string(s) +
          " is outside [0, block_levels = " + std::to_string(config.map.grid.block_levels) + "]");
    }
  }
  fs::create_directories(o.out);
  return config;
}

int run(const Options& o) {
  ros::Time::init();
  const auto start = Clock::now();
  const wavog_ros::Config config = prepare(o);
  std::unique_ptr<Session> session;
  const InputInfo info =
      isBag(o.input) ? runBag(o, config, &session) : runCarmen(o, config, &session);
  Session& s = *session;
  const double loop_s = std::chrono::duration<double>(Clock::now() - start).count();
  if (!o.quiet) {
    for (const auto& w : info.warnings) std::cerr << "wavog_offline: " << w << "\n";
  }

  const Json scales = writeScales(o, config, &s);
  s.map().save((fs::path(o.out) / "map.wavog").string());
  const wavog::MapStats stats = s.map().stats(true);
  const double wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  Json summary = summaryOf(o, config, info, s, stats, loop_s, wall_s);
  summary["scales"] = scales;
  summary["snapshots"] = s.snapshots();
  summary["read_error"] = info.read_error.empty() ? Json() : Json(info.read_error);
  wavog_tools::writeJson((fs::path(o.out) / "summary.json").string(), summary);

  if (!o.quiet) {
    std::cerr << std::fixed << std::setprecision(2) << "wavog_offline: " << s.integrated()
              << " scans integrated, " << s.droppedTotal() << " dropped, in " << wall_s << " s ("
              << std::setprecision(0)
              << (loop_s > 0 ? static_cast<double>(s.integrated()) / loop_s : 0.0) << " scans/s); "
              << stats.bytes << " bytes, " << std::setprecision(3) << bytesPerCell(stats)
              << " bytes per observed cell; wrote " << o.out << "/\n";
    for (const auto& [reason, n] : s.dropped()) {
      std::cerr << "wavog_offline:   dropped " << n << " (" << reason << ")\n";
    }
  }
  if (!info.read_error.empty()) {
    std::cerr << "wavog_offline: error: " << info.read_error << "; the maps hold the "
              << s.integrated() << " scans read before it\n";
    return 1;
  }
  if (s.integrated() == 0) {
    std::cerr << "wavog_offline: error: no scan could be integrated\n";
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return wavog_tools::toolMain(argc, argv, "wavog_offline", kDescription, addOptions, run);
}
