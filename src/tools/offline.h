// wavog_offline's parts shared by its two files: the options, the mapping session around
// WaveletMap::integrate, and the two input readers (offline_inputs.cpp: a rosbag through tf, or a
// CARMEN log with its logged poses). offline.cpp holds the command line, the outputs and main.
#ifndef WAVOG_MAPPING_TOOLS_OFFLINE_H_
#define WAVOG_MAPPING_TOOLS_OFFLINE_H_

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tool_support.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/io/image_io.h"
#include "wavog_mapping/ros/config.h"

namespace wavog_offline {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

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
  /// --laser-parent / --laser-pose: the scan frames held at laser_pose (x y z yaw pitch roll, m
  /// and rad) in laser_parent, for a bag whose tf lacks the laser (as the launch's arguments).
  std::string laser_parent;
  std::vector<double> laser_pose;
  double snapshot_every = 0.0;
  bool progress = true;
  bool quiet = false;
  int threads = -1;         // -1: the YAML's num_threads
  bool reflection = false;  // --reflection (else the YAML's)
  bool ndt = false;         // --ndt (else the YAML's)
};

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
  std::string laser_mount;  // "<parent> <- <frames>: x y z yaw pitch roll", with --laser-parent
  std::string read_error;
  std::vector<std::string> warnings;
  std::size_t motion_compensated =
      0;                             // scans re-binned over their sweep (bags with time_increment)
  std::size_t motion_fallbacks = 0;  // no tf at the sweep's end: integrated uncompensated
};

/// True when `path` starts with a rosbag's magic.
bool isBag(const std::string& path);

/// Maps a rosbag: its /tf into a tf2 buffer, then every scan of the chosen topics placed and
/// integrated through the node's conversions. Creates *session.
InputInfo runBag(const Options& o, const wavog_ros::Config& config,
                 std::unique_ptr<Session>* session);

/// Maps a CARMEN log with its logged laser poses. Creates *session.
InputInfo runCarmen(const Options& o, const wavog_ros::Config& config,
                    std::unique_ptr<Session>* session);

}  // namespace wavog_offline

#endif  // WAVOG_MAPPING_TOOLS_OFFLINE_H_
