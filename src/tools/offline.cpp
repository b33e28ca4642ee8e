// wavog_offline: maps a rosbag or a CARMEN log without a roscore, as fast as the core allows.
// Bags: /tf and /tf_static go into a tf2::BufferCore first, then every scan of the chosen topics is
// placed with lookupTransform(fixed frame, scan frame, stamp) and integrated through the node's
// conversions (scan checks, mirrored lasers, motion compensation over the sweep). CARMEN logs: the
// logged (corrected) laser poses are used as they are. The parameters come from the node's YAML
// through the one loader (wavog_ros::configFromXmlRpc). Writes per scale a PNG, a map_server PGM +
// YAML, the native map, summary.json and optional snapshots.
#include <getopt.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2/buffer_core.h>
#include <tf2_msgs/TFMessage.h>
#include <unistd.h>

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
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tool_support.h"
#include "wavog_mapping/core/motion_compensation.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/io/carmen_reader.h"
#include "wavog_mapping/io/image_io.h"
#include "wavog_mapping/ros/config.h"
#include "wavog_mapping/ros/conversions.h"
#include "wavog_mapping/ros/scan_placement.h"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr int kCropMargin = 2;           // unknown cells kept around the known part of a picture
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

void usage(std::FILE* out) {
  std::fprintf(
      out,
      "Usage: wavog_offline [options] INPUT\n"
      "Maps INPUT, a rosbag (LaserScan + /tf, /tf_static) or a CARMEN log (plain or .gz), without\n"
      "a roscore, and writes to the output folder: map_s<scale>.png (unknown in pale blue),\n"
      "map_s<scale>.pgm + .yaml (map_server), map.wavog (native map), summary.json.\n\n"
      "  -o, --out DIR           output folder (default offline_map; created)\n"
      "  -c, --config FILE       the node's YAML parameters (default: the compiled defaults)\n"
      "  --policy NAME           none|max|clamp|forget|clamp_lower|clamp_upper (over the YAML;\n"
      "                          the policy's documented defaults apply to keys the YAML omits)\n"
      "  --resolution M          finest cell size (over the YAML)\n"
      "  --scale LIST            scales to write, e.g. 0,2,3 (default: 0 and publish_scales)\n"
      "  --aggregation mean|max  how a coarse cell summarises its cells (over the YAML)\n"
      "  --max-scans N           integrate the first N scans only (0: all)\n"
      "  --topics LIST           bag scan topics (default: the YAML's inputs with --config, else\n"
      "                          every sensor_msgs/LaserScan topic of the bag)\n"
      "  --fixed-frame F         map frame (default: the YAML's map_frame); give the scan's own\n"
      "                          frame to map a bag without tf with the laser held fixed\n"
      "  --snapshot-every S      also write snapshots/t<seconds>_s<scale>.png every S s of log "
      "time\n"
      "  --threads N             threads updating one scan's blocks (num_threads; 0: one per\n"
      "                          core; the map is the same for every N)\n"
      "  --no-progress           no progress bar\n"
      "  --quiet                 only errors\n"
      "  -h, --help\n");
}

std::vector<int> parseScales(const std::string& text) {
  std::vector<int> scales;
  for (const auto& item : wavog_tools::splitList(text)) {
    scales.push_back(static_cast<int>(wavog_tools::parseInteger("--scale", item.c_str(), 0)));
  }
  if (scales.empty()) throw std::invalid_argument("--scale needs at least one scale");
  return scales;
}

bool parseOptions(int argc, char** argv, Options* o) {
  enum {
    kPolicy = 1000,
    kResolution,
    kScale,
    kAggregation,
    kMax,
    kTopics,
    kFixed,
    kSnapshot,
    kNoProgress,
    kQuiet,
    kThreads
  };
  const option longopts[] = {{"out", required_argument, nullptr, 'o'},
                             {"config", required_argument, nullptr, 'c'},
                             {"policy", required_argument, nullptr, kPolicy},
                             {"resolution", required_argument, nullptr, kResolution},
                             {"scale", required_argument, nullptr, kScale},
                             {"aggregation", required_argument, nullptr, kAggregation},
                             {"max-scans", required_argument, nullptr, kMax},
                             {"topics", required_argument, nullptr, kTopics},
                             {"fixed-frame", required_argument, nullptr, kFixed},
                             {"snapshot-every", required_argument, nullptr, kSnapshot},
                             {"no-progress", no_argument, nullptr, kNoProgress},
                             {"quiet", no_argument, nullptr, kQuiet},
                             {"threads", required_argument, nullptr, kThreads},
                             {"help", no_argument, nullptr, 'h'},
                             {nullptr, 0, nullptr, 0}};
  int c = 0;
  while ((c = getopt_long(argc, argv, "o:c:h", longopts, nullptr)) != -1) {
    switch (c) {
      case 'o':
        o->out = optarg;
        break;
      case 'c':
        o->config = optarg;
        break;
      case kPolicy:
        o->policy = optarg;
        break;
      case kResolution:
        o->resolution = wavog_tools::parseNumber("--resolution", optarg);
        break;
      case kScale:
        o->scales = parseScales(optarg);
        break;
      case kAggregation:
        o->aggregation = optarg;
        break;
      case kMax:
        o->max_scans = static_cast<std::size_t>(wavog_tools::parseInteger("--max-scans", optarg, 0));
        break;
      case kTopics:
        o->topics = wavog_tools::splitList(optarg);
        break;
      case kFixed:
        o->fixed_frame = wavog_tools::stripSlash(optarg);
        break;
      case kSnapshot:
        o->snapshot_every = wavog_tools::parseNumber("--snapshot-every", optarg);
        break;
      case kNoProgress:
        o->progress = false;
        break;
      case kQuiet:
        o->quiet = true;
        o->progress = false;
        break;
      case kThreads:
        o->threads = static_cast<int>(wavog_tools::parseInteger("--threads", optarg, 0));
        break;
      case 'h':
        usage(stdout);
        std::exit(0);
      default:
        return false;
    }
  }
  if (argc - optind != 1) return false;
  o->input = argv[optind];
  if (!(o->snapshot_every >= 0.0)) throw std::invalid_argument("--snapshot-every must be >= 0");
  return true;
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
    // Old bags carry frame ids with a leading '/', which tf2 rejects: strip it (the bag's tf
    // frames were stripped the same way).
    scan->header.frame_id = wavog_tools::stripSlash(scan->header.frame_id);
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

/// The raster cropped to its known cells plus a margin (the whole raster if nothing is known).
wavog::Raster cropToKnown(const wavog::Raster& r) {
  const std::int64_t w = r.box.width();
  const std::int64_t h = r.box.height();
  std::int64_t x0 = w, y0 = h, x1 = -1, y1 = -1;
  for (std::int64_t y = 0; y < h; ++y) {
    for (std::int64_t x = 0; x < w; ++x) {
      if (r.known[static_cast<std::size_t>(y * w + x)]) {
        x0 = std::min(x0, x);
        x1 = std::max(x1, x);
        y0 = std::min(y0, y);
        y1 = std::max(y1, y);
      }
    }
  }
  if (x1 < 0) return r;
  x0 = std::max<std::int64_t>(0, x0 - kCropMargin);
  y0 = std::max<std::int64_t>(0, y0 - kCropMargin);
  x1 = std::min<std::int64_t>(w - 1, x1 + kCropMargin);
  y1 = std::min<std::int64_t>(h - 1, y1 + kCropMargin);
  wavog::Raster c = r;
  c.box = wavog::CellBox{r.box.min_x + x0, r.box.min_y + y0, r.box.min_x + x1 + 1,
                         r.box.min_y + y1 + 1};
  const std::int64_t cw = c.box.width();
  c.log_odds.assign(static_cast<std::size_t>(cw * c.box.height()), 0.0f);
  c.known.assign(c.log_odds.size(), 0);
  for (std::int64_t y = y0; y <= y1; ++y) {
    const std::size_t src = static_cast<std::size_t>(y * w + x0);
    const std::size_t dst = static_cast<std::size_t>((y - y0) * cw);
    std::copy_n(r.log_odds.begin() + static_cast<std::ptrdiff_t>(src), cw,
                c.log_odds.begin() + static_cast<std::ptrdiff_t>(dst));
    std::copy_n(r.known.begin() + static_cast<std::ptrdiff_t>(src), cw,
                c.known.begin() + static_cast<std::ptrdiff_t>(dst));
  }
  return c;
}

int run(const Options& o) {
  const auto start = Clock::now();
  {
    std::ifstream probe(o.input, std::ios::binary);
    if (fs::is_directory(o.input) || !probe) {
      throw std::runtime_error(o.input + ": cannot open: " +
                               (fs::is_directory(o.input) ? std::string("is a directory")
                                                          : std::string(std::strerror(errno))));
    }
  }
  std::vector<std::string> unknown;
  const wavog_ros::Config config = loadConfig(o, &unknown);
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

  std::unique_ptr<Session> session;
  const InputInfo info =
      isBag(o.input) ? runBag(o, config, &session) : runCarmen(o, config, &session);
  Session& s = *session;
  const double loop_s = std::chrono::duration<double>(Clock::now() - start).count();
  if (!o.quiet) {
    for (const auto& w : info.warnings) std::cerr << "wavog_offline: " << w << "\n";
  }

  // Pictures and map_server maps per scale, cropped to the observed part.
  wavog::WaveletMap& map = s.map();
  std::ostringstream scales_json;
  bool first = true;
  for (int scale : s.scales()) {
    wavog::CellBox box;
    if (!map.bounds(scale, &box)) break;
    const wavog::Raster raster =
        cropToKnown(map.exportScale(scale, box, config.ros.scale_aggregation));
    const std::string base = "map_s" + std::to_string(scale);
    wavog::writePng((fs::path(o.out) / (base + ".png")).string(), wavog::renderRgb(raster));
    wavog::writeMapServerMap((fs::path(o.out) / base).string(), raster);
    scales_json << (first ? "" : ",") << "\n    {\"scale\": " << scale
                << ", \"cell_size_m\": " << wavog_tools::jsonNumber(raster.cell_size)
                << ", \"width\": " << raster.box.width() << ", \"height\": " << raster.box.height()
                << ", \"origin\": [" << wavog_tools::jsonNumber(raster.originX()) << ", "
                << wavog_tools::jsonNumber(raster.originY()) << "], \"png\": \"" << base
                << ".png\", \"pgm\": \"" << base << ".pgm\", \"yaml\": \"" << base << ".yaml\"}";
    first = false;
  }
  const std::string native = (fs::path(o.out) / "map.wavog").string();
  map.save(native);
  const wavog::MapStats stats = map.stats(true);
  const double wall_s = std::chrono::duration<double>(Clock::now() - start).count();

  std::ostringstream json;
  json << "{\n  \"input\": " << wavog_tools::jsonString(o.input) << ",\n  \"input_type\": \""
       << info.type << "\""
       << ",\n  \"config\": " << (o.config.empty() ? "null" : wavog_tools::jsonString(o.config))
       << ",\n  \"policy\": \"" << wavog::toString(config.map.policy.type) << "\""
       << ",\n  \"resolution_m\": " << wavog_tools::jsonNumber(config.map.grid.resolution)
       << ",\n  \"aggregation\": \"" << wavog_ros::toString(config.ros.scale_aggregation) << "\""
       << ",\n  \"fixed_frame\": " << wavog_tools::jsonString(info.fixed_frame)
       << ",\n  \"topics\": [";
  for (std::size_t i = 0; i < info.topics.size(); ++i) {
    json << (i ? ", " : "") << wavog_tools::jsonString(info.topics[i]);
  }
  std::size_t dropped_total = 0;
  for (const auto& [reason, n] : s.dropped()) dropped_total += n;
  json << "],\n  \"scans_integrated\": " << s.integrated()
       << ",\n  \"scans_dropped\": " << dropped_total << ",\n  \"dropped_by_reason\": {";
  first = true;
  for (const auto& [reason, n] : s.dropped()) {
    json << (first ? "" : ", ") << wavog_tools::jsonString(reason) << ": " << n;
    first = false;
  }
  const double per_cell = stats.observed_cells > 0 ? static_cast<double>(stats.bytes) /
                                                         static_cast<double>(stats.observed_cells)
                                                   : 0.0;
  json << "},\n  \"beams\": {\"hit\": " << s.beamsHit() << ", \"no_return\": " << s.beamsNoReturn()
       << ", \"invalid\": " << s.beamsInvalid() << "}"
       << ",\n  \"log_duration_s\": " << wavog_tools::jsonNumber(s.logDuration())
       << ",\n  \"wall_time_s\": " << wavog_tools::jsonNumber(wall_s)
       << ",\n  \"read_and_integrate_s\": " << wavog_tools::jsonNumber(loop_s)
       << ",\n  \"integrate_s\": " << wavog_tools::jsonNumber(s.integrateSeconds())
       << ",\n  \"scans_per_s\": "
       << wavog_tools::jsonNumber(loop_s > 0 ? static_cast<double>(s.integrated()) / loop_s : 0.0)
       << ",\n  \"integrate_scans_per_s\": "
       << wavog_tools::jsonNumber(s.integrateSeconds() > 0
                                      ? static_cast<double>(s.integrated()) / s.integrateSeconds()
                                      : 0.0)
       << ",\n  \"motion_compensated\": " << info.motion_compensated
       << ",\n  \"motion_fallbacks\": " << info.motion_fallbacks
       << ",\n  \"nodes_visited_per_scan\": "
       << wavog_tools::jsonNumber(s.integrated() > 0 ? static_cast<double>(s.nodesVisited()) /
                                                           static_cast<double>(s.integrated())
                                                     : 0.0)
       << ",\n  \"map\": {\"blocks\": " << stats.blocks << ", \"nodes\": " << stats.nodes
       << ", \"bytes\": " << stats.bytes << ", \"observed_cells\": " << stats.observed_cells
       << ", \"bytes_per_observed_cell\": " << wavog_tools::jsonNumber(per_cell) << "}"
       << ",\n  \"native_map\": \"map.wavog\",\n  \"scales\": [" << scales_json.str() << "\n  ]"
       << ",\n  \"snapshots\": [";
  for (std::size_t i = 0; i < s.snapshots().size(); ++i) {
    json << (i ? ", " : "") << wavog_tools::jsonString(s.snapshots()[i]);
  }
  json << "],\n  \"read_error\": "
       << (info.read_error.empty() ? "null" : wavog_tools::jsonString(info.read_error)) << "\n}\n";
  std::ofstream((fs::path(o.out) / "summary.json").string()) << json.str();

  if (!o.quiet) {
    std::cerr << std::fixed << std::setprecision(2) << "wavog_offline: " << s.integrated()
              << " scans integrated, " << dropped_total << " dropped, in " << wall_s << " s ("
              << std::setprecision(0)
              << (loop_s > 0 ? static_cast<double>(s.integrated()) / loop_s : 0.0) << " scans/s); "
              << stats.bytes << " bytes, " << std::setprecision(3) << per_cell
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
  Options options;
  return wavog_tools::toolMain(
      "wavog_offline", [&] { return parseOptions(argc, argv, &options); }, usage,
      [&] {
        ros::Time::init();
        return run(options);
      });
}
