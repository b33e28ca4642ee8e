// wavog_offline: maps a rosbag or a CARMEN log without a roscore, as fast as the core allows.
// Bags: /tf and /tf_static go into a tf2::BufferCore first, then every scan of the chosen topics is
// placed with lookupTransform(fixed frame, scan frame, stamp) and integrated through the node's
// conversions (scan checks, mirrored lasers, motion compensation over the sweep). CARMEN logs: the
// logged (corrected) laser poses are used as they are. The parameters come from the node's YAML
// through the one loader (wavog_ros::configFromXmlRpc). Writes per scale a PNG, a map_server PGM +
// YAML, the native map, summary.json and optional snapshots.
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
#include "wavog_mapping/ros/config.h"
#include "wavog_mapping/ros/conversions.h"
#include "wavog_mapping/ros/scan_placement.h"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using Json = nlohmann::ordered_json;

constexpr double kTfCacheMargin = 60.0;  // s added to the bag's duration for the tf buffer

struct Options {
  std::string input;
  std::string out = "offline_map";
  std::string config;
  std::string policy;
  std::string aggregation;
  double resolution = 0.0;
  std::vector<int> scales;
  std::size_t max_scans = 0;
  std::vector<std::string> topics;
  std::string fixed_frame;
  double snapshot_every = 0.0;
  bool progress = true;
  bool quiet = false;
  int threads = -1;  // -1: the YAML's num_threads
};

std::vector<int> parseScales(const std::string& text) {
  std::vector<int> scales;
  for (const auto& item : wavog_tools::splitList(text)) {
    scales.push_back(static_cast<int>(wavog_tools::parseInteger("--scale", item.c_str(), 0)));
  }
  if (scales.empty()) throw std::invalid_argument("--scale needs at least one scale");
  return scales;
}

/// What --help says first.
constexpr const char* kDescription =
    "Maps INPUT, a rosbag (LaserScan + /tf, /tf_static) or a CARMEN log (plain or .gz), without "
    "a roscore, and writes to the output folder: map_s<scale>.png (unknown in pale blue), "
    "map_s<scale>.pgm + .yaml (map_server), map.wavog (native map), summary.json.";

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
  wavog_tools::addNumber(app, "--snapshot-every", &o->snapshot_every,
                         "also write snapshots/t<seconds>_s<scale>.png every S s of log time "
                         "(0: none)");
  wavog_tools::addInteger(app, "--threads", &o->threads, 0,
                          "threads updating one scan's blocks (num_threads; 0: one per core; the "
                          "map is the same for every N)")
      ->default_str("the YAML's");
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
  if (o.resolution > 0.0) root["resolution"] = o.resolution;
  if (o.threads >= 0) root["num_threads"] = o.threads;
  if (!o.aggregation.empty()) root["scale_aggregation"] = o.aggregation;
  try {
    return wavog_ros::configFromXmlRpc(root, unknown);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument((o.config.empty() ? std::string("options") : o.config) + ": " +
                                e.what());
  }
}

bool isBag(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[9] = {0};
  in.read(head, 8);
  return std::string(head, 8) == "#ROSBAG ";
}

/// Counts, snapshots and progress around WaveletMap::integrate, shared by both inputs.
class Session {
 public:
  Session(const Options& o, const wavog_ros::Config& config, std::size_t total)
      : o_(o), config_(config), map_(config.map), progress_(total, o.progress) {}

  void integrate(const wavog::Pose2& pose, const wavog::ScanView& view, double stamp) {
    if (!have_first_) {
      first_stamp_ = stamp;
      have_first_ = true;
    }
    last_stamp_ = stamp;
    const auto t0 = Clock::now();
    const wavog::IntegrateStats s = map_.integrate(pose, view);
    integrate_s_ += std::chrono::duration<double>(Clock::now() - t0).count();
    if (s.status == wavog::ScanStatus::kOk) {
      ++integrated_;
      nodes_visited_ += s.nodes_visited;
    } else {
      drop(std::string("core_") + wavog::toString(s.status));
    }
    beams_hit_ += s.beams_hit;
    beams_no_return_ += s.beams_no_return;
    beams_invalid_ += s.beams_invalid;
    ++done_;
    maybeSnapshot(stamp);
    progress_.update(done_);
  }

  void drop(const std::string& reason) { ++dropped_[reason]; }
  /// A scan that was considered but not integrated (progress advances).
  void skip(const std::string& reason) {
    drop(reason);
    ++done_;
    progress_.update(done_);
  }

  void finish() { progress_.finish(done_); }

  wavog::WaveletMap& map() { return map_; }
  std::size_t done() const { return done_; }
  std::size_t integrated() const { return integrated_; }
  const std::map<std::string, std::size_t>& dropped() const { return dropped_; }
  std::size_t droppedTotal() const {
    std::size_t n = 0;
    for (const auto& reason : dropped_) n += reason.second;
    return n;
  }
  double logDuration() const { return have_first_ ? last_stamp_ - first_stamp_ : 0.0; }
  double integrateSeconds() const { return integrate_s_; }
  std::uint64_t nodesVisited() const { return nodes_visited_; }
  std::uint64_t beamsHit() const { return beams_hit_; }
  std::uint64_t beamsNoReturn() const { return beams_no_return_; }
  std::uint64_t beamsInvalid() const { return beams_invalid_; }
  const std::vector<std::string>& snapshots() const { return snapshots_; }
  int snapshotScale() const { return scales().front(); }

  std::vector<int> scales() const {
    if (!o_.scales.empty()) return o_.scales;
    std::vector<int> s = {0};
    for (int k : config_.ros.publish_scales) {
      if (std::find(s.begin(), s.end(), k) == s.end()) s.push_back(k);
    }
    return s;
  }

 private:
  void maybeSnapshot(double stamp) {
    if (o_.snapshot_every <= 0.0) return;
    if (stamp - first_stamp_ < next_snapshot_) return;
    next_snapshot_ =
        (std::floor((stamp - first_stamp_) / o_.snapshot_every) + 1.0) * o_.snapshot_every;
    const int scale = snapshotScale();
    wavog::CellBox box;
    if (!map_.bounds(scale, &box)) return;
    const fs::path dir = fs::path(o_.out) / "snapshots";
    fs::create_directories(dir);
    std::ostringstream name;
    name << "t" << std::setw(7) << std::setfill('0') << std::fixed << std::setprecision(1)
         << (stamp - first_stamp_) << "_s" << scale << ".png";
    const wavog::Raster raster = map_.exportScale(scale, box, config_.ros.scale_aggregation);
    wavog::writePng((dir / name.str()).string(), wavog::renderRgb(raster));
    snapshots_.push_back("snapshots/" + name.str());
  }

  const Options& o_;
  const wavog_ros::Config& config_;
  wavog::WaveletMap map_;
  wavog_tools::ProgressBar progress_;
  std::size_t done_ = 0;
  std::size_t integrated_ = 0;
  std::map<std::string, std::size_t> dropped_;
  bool have_first_ = false;
  double first_stamp_ = 0.0;
  double last_stamp_ = 0.0;
  double next_snapshot_ = 0.0;
  double integrate_s_ = 0.0;
  std::uint64_t nodes_visited_ = 0;
  std::uint64_t beams_hit_ = 0;
  std::uint64_t beams_no_return_ = 0;
  std::uint64_t beams_invalid_ = 0;
  std::vector<std::string> snapshots_;
};

/// What the input said besides its scans, for the summary.
struct InputInfo {
  std::string type;  // "bag" or "carmen"
  std::vector<std::string> topics;
  std::string fixed_frame;
  std::string read_error;
  std::vector<std::string> warnings;
  std::size_t motion_compensated =
      0;                             // scans re-binned over their sweep (bags with time_increment)
  std::size_t motion_fallbacks = 0;  // no tf at the sweep's end: integrated uncompensated
};

std::string describeBagTopics(const rosbag::Bag& bag) {
  rosbag::View all(bag);
  std::map<std::string, std::pair<std::string, std::size_t>> topics;
  for (const rosbag::ConnectionInfo* c : all.getConnections()) {
    topics[c->topic].first = c->datatype;
  }
  for (const auto& [topic, info] : topics) {
    rosbag::View one(bag, rosbag::TopicQuery(topic));
    topics[topic].second = one.size();
  }
  std::ostringstream s;
  for (const auto& [topic, info] : topics) {
    s << "\n  " << topic << " (" << info.first << ", " << info.second << " msgs)";
  }
  return topics.empty() ? std::string("\n  (no topics)") : s.str();
}

std::string normaliseTopic(const std::string& t) { return t.empty() || t[0] == '/' ? t : "/" + t; }

InputInfo runBag(const Options& o, const wavog_ros::Config& config,
                 std::unique_ptr<Session>* session) {
  InputInfo info;
  info.type = "bag";
  info.fixed_frame =
      o.fixed_frame.empty() ? wavog_tools::stripSlash(config.ros.map_frame) : o.fixed_frame;
  rosbag::Bag bag;
  try {
    bag.open(o.input, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    throw std::runtime_error(o.input + ": cannot read the bag: " + e.what());
  }

  // Scan topics: asked for, or every LaserScan topic of the bag.
  std::map<std::string, std::string> bag_topics;  // normalised name -> name in the bag
  std::vector<std::string> laser_topics;
  {
    rosbag::View all(bag);
    for (const rosbag::ConnectionInfo* c : all.getConnections()) {
      bag_topics[normaliseTopic(c->topic)] = c->topic;
      if (c->datatype == "sensor_msgs/LaserScan" &&
          std::find(laser_topics.begin(), laser_topics.end(), c->topic) == laser_topics.end()) {
        laser_topics.push_back(c->topic);
      }
    }
  }
  std::vector<std::string> wanted = o.topics;
  if (wanted.empty() && !o.config.empty()) {
    for (const auto& input : config.ros.inputs) wanted.push_back(input.topic);
  }
  if (wanted.empty()) {
    if (laser_topics.empty()) {
      throw std::runtime_error(o.input + ": the bag has no sensor_msgs/LaserScan topic; it has:" +
                               describeBagTopics(bag));
    }
    info.topics = laser_topics;
  } else {
    for (const auto& t : wanted) {
      const auto it = bag_topics.find(normaliseTopic(t));
      if (it == bag_topics.end()) {
        throw std::runtime_error(o.input + ": the bag has no topic '" + t +
                                 "' (use --topics); it has:" + describeBagTopics(bag));
      }
      info.topics.push_back(it->second);
    }
  }

  // tf: the whole bag into one buffer first, so each scan sees tf before and after its stamp.
  rosbag::View tf_view(
      bag, rosbag::TopicQuery(std::vector<std::string>{"/tf", "/tf_static", "tf", "tf_static"}));
  const double duration =
      (tf_view.size() > 0) ? (tf_view.getEndTime() - tf_view.getBeginTime()).toSec() : 0.0;
  tf2::BufferCore tf(ros::Duration(duration + kTfCacheMargin));
  for (const rosbag::MessageInstance& m : tf_view) {
    const auto msg = m.instantiate<tf2_msgs::TFMessage>();
    if (!msg) continue;
    const bool is_static = m.getTopic().find("tf_static") != std::string::npos;
    for (geometry_msgs::TransformStamped t : msg->transforms) {
      t.header.frame_id = wavog_tools::stripSlash(t.header.frame_id);
      t.child_frame_id = wavog_tools::stripSlash(t.child_frame_id);
      tf.setTransform(t, "bag", is_static);
    }
  }

  rosbag::View scans(bag, rosbag::TopicQuery(info.topics));
  std::size_t total = scans.size();
  if (o.max_scans > 0) total = std::min(total, o.max_scans);
  *session = std::make_unique<Session>(o, config, total);
  Session& s = **session;
  std::string first_tf_error;
  std::set<std::string> scan_frames;
  std::set<std::string> slash_warned;  // topics whose frame_id had a leading '/'
  wavog::MotionCompensator compensator;
  wavog_ros::PlacementOptions placement_options;
  placement_options.fixed_frame = info.fixed_frame;
  placement_options.motion_compensation = config.ros.motion_compensation;
  for (const rosbag::MessageInstance& m : scans) {
    if (s.done() >= total) break;
    const auto scan = m.instantiate<sensor_msgs::LaserScan>();
    if (!scan) {
      s.skip("not_a_laserscan");
      continue;
    }
    // Old bags carry frame ids with a leading '/', which tf2 rejects: strip it, saying so once per
    // topic as the node does (the bag's tf frames were stripped the same way).
    const std::string received = scan->header.frame_id;
    if (wavog_ros::stripFrameSlash(&scan->header.frame_id) &&
        slash_warned.insert(m.getTopic()).second) {
      info.warnings.push_back(m.getTopic() + ": " + wavog_ros::frameSlashWarning(received));
    }
    const std::string& frame = scan->header.frame_id;
    scan_frames.insert(frame);
    wavog_ros::DropReason reason = wavog_ros::DropReason::kEmpty;
    if (!wavog_ros::checkScan(*scan, &reason)) {
      s.skip(std::string("scan_") + wavog_ros::toString(reason));
      continue;
    }
    // The node's placement (scan_placement.h): pose at the first and last beam from tf, mirrored
    // view for an upside-down laser, motion compensation over the sweep.
    const wavog_ros::ScanPlacement placement = wavog_ros::placeScan(tf, *scan, placement_options);
    if (!placement.placed()) {
      if (first_tf_error.empty()) first_tf_error = placement.error;
      s.skip(placement.failure == wavog_ros::TfFailure::kExtrapolation ? "tf_extrapolation"
                                                                        : "tf_unavailable");
      continue;
    }
    info.motion_fallbacks += placement.motion_fallback ? 1 : 0;
    info.motion_compensated += placement.compensate ? 1 : 0;
    wavog::Pose2 pose;
    const wavog::ScanView view = placement.placedView(*scan, &compensator, &pose);
    s.integrate(pose, view, scan->header.stamp.toSec());
  }
  s.finish();
  if (s.integrated() == 0 && !first_tf_error.empty()) {
    std::vector<std::string> frames;
    tf._getFrameStrings(frames);
    std::ostringstream msg;
    msg << o.input << ": tf never connects the scan frame";
    for (const auto& f : scan_frames) msg << " '" << f << "'";
    msg << " to the fixed frame '" << info.fixed_frame << "' (" << first_tf_error
        << ").\n  Frames in the bag's tf: ";
    if (frames.empty()) msg << "none (the bag has no /tf or /tf_static)";
    for (std::size_t i = 0; i < frames.size(); ++i) msg << (i ? ", " : "") << frames[i];
    msg << ".\n  Use --fixed-frame <frame> (e.g. the scan frame, to map with the laser held "
           "fixed).";
    throw std::runtime_error(msg.str());
  }
  return info;
}

InputInfo runCarmen(const Options& o, const wavog_ros::Config& config,
                    std::unique_ptr<Session>* session) {
  InputInfo info;
  info.type = "carmen";
  info.fixed_frame = "log";
  const wavog_tools::CarmenLogPlan plan = wavog_tools::planCarmenLog(o.input);
  for (const auto& l : plan.lasers) {
    if (l.used) info.topics.push_back(l.type);
  }
  if (plan.skipped_duplicates > 0) {
    info.warnings.push_back(
        std::to_string(plan.skipped_duplicates) +
        " ROBOTLASER1 scans skipped: the log's FLASER lines hold the same laser");
  }
  std::size_t total = plan.scans_used;
  if (o.max_scans > 0) total = std::min(total, o.max_scans);
  *session = std::make_unique<Session>(o, config, total);
  Session& s = **session;
  wavog::CarmenReader reader(o.input, false);
  wavog::CarmenScan scan;
  try {
    // Read on to the end (not just `total` scans), so that a truncated stream is reported.
    while ((o.max_scans == 0 || s.done() < o.max_scans) && reader.next(&scan)) {
      if (plan.laserFor(scan.type) == nullptr) continue;
      s.integrate(scan.laser_pose, scan.view(0.0), scan.ipc_timestamp);
    }
  } catch (const std::runtime_error& e) {
    info.read_error = e.what();
  }
  s.finish();
  for (const auto& e : reader.errors()) {
    info.warnings.push_back("skipped malformed line: " + e);
    s.drop("malformed_line");
  }
  if (total == 0 && info.read_error.empty()) {
    throw std::runtime_error(o.input + ": no FLASER, RLASER or ROBOTLASER1 scan found");
  }
  return info;
}

/// Per scale: a PNG and a map_server map, cropped to the observed part; their entries of
/// summary.json's "scales".
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
    wavog::writeMapServerMap((fs::path(o.out) / base).string(), raster);
    scales.push_back({{"scale", scale},
                      {"cell_size_m", raster.cell_size},
                      {"width", raster.box.width()},
                      {"height", raster.box.height()},
                      {"origin", {raster.originX(), raster.originY()}},
                      {"png", base + ".png"},
                      {"pgm", base + ".pgm"},
                      {"yaml", base + ".yaml"}});
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
                    {"bytes", stats.bytes},
                    {"observed_cells", stats.observed_cells},
                    {"bytes_per_observed_cell", bytesPerCell(stats)}};
  summary["native_map"] = "map.wavog";
  return summary;
}

/// The input readable, the configuration loaded (unknown keys warned about), the scales in
/// range, the output folder made.
wavog_ros::Config prepare(const Options& o) {
  if (!(o.snapshot_every >= 0.0)) throw std::invalid_argument("--snapshot-every must be >= 0");
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
