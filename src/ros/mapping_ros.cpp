// MappingRos (see mapping_ros.h): messages in, core calls, messages out.
#include "wavog_mapping/ros/mapping_ros.h"

#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/update_functions.h>
#include <dynamic_reconfigure/server.h>
#include <map_msgs/OccupancyGridUpdate.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <array>
#include <boost/make_shared.hpp>
#include <boost/thread/recursive_mutex.hpp>
#include <cctype>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include "wavog_mapping/ClearRegion.h"
#include "wavog_mapping/MapperStatus.h"
#include "wavog_mapping/MappingConfig.h"
#include "wavog_mapping/SaveMap.h"
#include "wavog_mapping/core/motion_compensation.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/io/image_io.h"
#include "wavog_mapping/ros/config.h"
#include "wavog_mapping/ros/conversions.h"

namespace wavog_ros {
namespace {

using LaserScan = sensor_msgs::LaserScan;
using ScanFilter = tf2_ros::MessageFilter<LaserScan>;
using Clock = std::chrono::steady_clock;

/// Stamps (or the clock) going back by more than this (s) are a time jump (e.g. a bag restart).
constexpr double kTimeJumpThreshold = 1.0;
/// Subscriber queue per input: bursts (several drivers on one host) must not be lost before the
/// scans reach the tf MessageFilter, whose own queue is the queue_size parameter.
constexpr std::uint32_t kSubscriberQueue = 50;
/// Seconds between two warnings of the same input and reason.
constexpr double kWarnPeriod = 5.0;

/// Counters of one input; guarded by Impl::mutex_.
struct InputCounters {
  std::uint64_t received = 0;
  std::uint64_t integrated = 0;
  std::array<std::uint64_t, kNumDropReasons> dropped{};
  std::uint64_t time_jumps = 0;
  std::uint64_t motion_fallbacks = 0;
  std::uint64_t beams_invalid = 0;
  std::uint64_t beams_no_return = 0;
  std::uint64_t received_in_period = 0;  ///< for the measured rate in ~status
  ros::Time last_stamp;                  ///< of the last integrated scan
  ros::Time last_received_stamp;         ///< of the last received scan (time-jump check)
  ros::Time last_receipt;                ///< clock time of the last receipt (stale check)
  double rate = 0.0;                     ///< measured over the last status period (Hz)
};

struct Input {
  InputConfig config;
  std::string topic;  ///< resolved name
  ros::Subscriber sub;
  std::unique_ptr<ScanFilter> filter;
  InputCounters c;
  std::array<ros::WallTime, kNumDropReasons + 1> last_warn;  ///< + 1: time jumps
  double min_freq = 0.0;  ///< diagnostics bounds (the FrequencyStatus keeps pointers to them)
  double max_freq = 0.0;
  diagnostic_updater::FrequencyStatus* freq = nullptr;  ///< owned by Impl::freq_; may be null
};

/// Parses "2, 3,4" into scales; false on a malformed entry.
bool parseScales(const std::string& text, std::vector<int>* scales) {
  scales->clear();
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    item.erase(std::remove_if(item.begin(), item.end(),
                              [](unsigned char c) { return std::isspace(c) != 0; }),
               item.end());
    if (item.empty()) continue;
    std::size_t used = 0;
    try {
      scales->push_back(std::stoi(item, &used));
    } catch (const std::exception&) {
      return false;
    }
    if (used != item.size()) return false;
  }
  return true;
}

std::string joinScales(const std::vector<int>& scales) {
  std::string out;
  for (int s : scales) out += (out.empty() ? "" : ",") + std::to_string(s);
  return out;
}

wavog::Raster emptyRaster(int scale, double resolution) {
  wavog::Raster r;
  r.scale = scale;
  r.cell_size = resolution * static_cast<double>(1 << scale);
  return r;
}

}  // namespace

struct MappingRos::Impl {
  Impl(const ros::NodeHandle& nh, const ros::NodeHandle& pnh);
  ~Impl();

  void onScan(Input* in, const LaserScan::ConstPtr& scan);
  void onTransformable(Input* in, const LaserScan::ConstPtr& scan);
  void onFilterFailure(Input* in, tf2_ros::filter_failure_reasons::FilterFailureReason reason);
  void dropLocked(Input* in, DropReason reason, const std::string& detail);
  void warnLocked(Input* in, std::size_t slot, const std::string& text);

  void onPublishTimer(const ros::TimerEvent&);
  void onUpdateTimer(const ros::TimerEvent&);
  bool onReset(std_srvs::Empty::Request&, std_srvs::Empty::Response&);
  bool onClearRegion(wavog_mapping::ClearRegion::Request& req,
                     wavog_mapping::ClearRegion::Response& res);
  bool onSaveMap(wavog_mapping::SaveMap::Request& req, wavog_mapping::SaveMap::Response& res);
  void onReconfigure(wavog_mapping::MappingConfig& rc, std::uint32_t level);
  void advertiseScalesLocked(const std::vector<int>& scales);
  void markAllDirtyLocked();

  void diagnoseInput(const Input* in, diagnostic_updater::DiagnosticStatusWrapper& stat);
  void diagnoseMapper(diagnostic_updater::DiagnosticStatusWrapper& stat);

  ros::NodeHandle nh_, pnh_;
  Config config_;  // the map part changes only through setPolicy(); guarded by mutex_

  // tf first: the filters (in inputs_) refer to the buffer and are destroyed before it.
  std::unique_ptr<tf2_ros::Buffer> buffer_;
  /// Our own /tf and /tf_static subscribers instead of tf2_ros::TransformListener: Debian's
  /// tf2_ros (0.7.6) MessageFilter::add() registers its transformable request before queueing the
  /// message, so a transform inserted by another thread in between notifies nobody and the scan
  /// waits in the filter forever (seen in fast bag playback: a few scans of 300 never processed).
  /// tf_mutex_ serialises tf insertion with MessageFilter::add() and buffer clearing.
  std::mutex tf_mutex_;
  ros::Subscriber tf_sub_, tf_static_sub_;
  void onTf(const tf2_msgs::TFMessage::ConstPtr& msg, bool is_static);

  /// The one lock: map_, compensator_, every Input::c, the statistics, the dirty box, the scale
  /// publishers and config_. Never held while publishing or while waiting on tf.
  std::mutex mutex_;
  wavog::WaveletMap map_;
  wavog::MotionCompensator compensator_;
  std::vector<std::unique_ptr<Input>> inputs_;
  ros::Time last_now_;  ///< clock at the last scan (backwards-jump check)
  std::uint64_t clock_jumps_ = 0;
  // Integration time over the current status period.
  double integrate_time_sum_ = 0.0;
  double integrate_time_max_ = 0.0;
  std::uint64_t integrate_count_ = 0;
  double last_mean_ = 0.0, last_max_ = 0.0;  ///< of the last finished period (diagnostics)
  double publish_time_ = 0.0;
  ros::Time last_status_time_;
  std::uint64_t tf_failures_reported_ = 0;  ///< tf failures at the last diagnostics update
  // Region touched since the last map_updates message (map frame, m).
  bool dirty_ = false;
  double dirty_min_x_ = 0, dirty_min_y_ = 0, dirty_max_x_ = 0, dirty_max_y_ = 0;
  bool have_full_ = false;
  wavog::CellBox last_full_box_;  ///< scale-0 box of the last full `map`
  std::map<int, ros::Publisher> scale_pubs_;

  ros::Publisher map_pub_, update_pub_, status_pub_;
  ros::ServiceServer reset_srv_, clear_srv_, save_srv_;
  ros::Timer publish_timer_, update_timer_, diag_timer_;

  std::unique_ptr<diagnostic_updater::Updater> updater_;
  std::vector<std::unique_ptr<diagnostic_updater::FrequencyStatus>> freq_;

  boost::recursive_mutex reconfigure_mutex_;
  std::unique_ptr<dynamic_reconfigure::Server<wavog_mapping::MappingConfig>> reconfigure_;
};

MappingRos::Impl::Impl(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
    : nh_(nh),
      pnh_(pnh),
      config_([&] {
        std::vector<std::string> unknown;
        Config c = loadConfig(pnh, &unknown);
        for (const auto& key : unknown) {
          ROS_WARN("%s: unknown parameter '%s' ignored (config/default.yaml lists every key)",
                   pnh.getNamespace().c_str(), key.c_str());
        }
        return c;
      }()),
      map_(config_.map) {
  const RosParams& rp = config_.ros;
  if (!rp.map_file.empty()) {
    try {
      map_.load(rp.map_file);
    } catch (const wavog::MapIoError& e) {
      throw std::runtime_error("map_file: cannot load '" + rp.map_file + "': " + e.what());
    }
    ROS_INFO("%s: loaded map_file '%s'", pnh_.getNamespace().c_str(), rp.map_file.c_str());
  }

  buffer_ = std::make_unique<tf2_ros::Buffer>(ros::Duration(rp.tf_cache_time));
  ros::NodeHandle root;
  tf_sub_ = root.subscribe<tf2_msgs::TFMessage>(
      "/tf", 100,
      boost::function<void(const tf2_msgs::TFMessage::ConstPtr&)>(
          [this](const tf2_msgs::TFMessage::ConstPtr& m) { onTf(m, false); }),
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  tf_static_sub_ = root.subscribe<tf2_msgs::TFMessage>(
      "/tf_static", 100,
      boost::function<void(const tf2_msgs::TFMessage::ConstPtr&)>(
          [this](const tf2_msgs::TFMessage::ConstPtr& m) { onTf(m, true); }),
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());

  map_pub_ = nh_.advertise<nav_msgs::OccupancyGrid>("map", 1, true);
  update_pub_ = nh_.advertise<map_msgs::OccupancyGridUpdate>("map_updates", 10);
  status_pub_ = pnh_.advertise<wavog_mapping::MapperStatus>("status", 10);
  advertiseScalesLocked(rp.publish_scales);  // not yet shared: no lock needed

  updater_ = std::make_unique<diagnostic_updater::Updater>(nh_, pnh_, pnh_.getNamespace());
  updater_->setHardwareID("wavog_mapping");
  updater_->add("mapper",
                [this](diagnostic_updater::DiagnosticStatusWrapper& s) { diagnoseMapper(s); });

  for (const InputConfig& ic : rp.inputs) {
    auto in = std::make_unique<Input>();
    in->config = ic;
    in->topic = nh_.resolveName(ic.topic);
    in->min_freq = ic.expected_rate * (1.0 - rp.rate_tolerance);
    in->max_freq = ic.expected_rate * (1.0 + rp.rate_tolerance);
    Input* raw = in.get();
    in->filter = std::make_unique<ScanFilter>(*buffer_, rp.map_frame,
                                              static_cast<std::uint32_t>(rp.queue_size), nh_);
    in->filter->setTolerance(ros::Duration(rp.tf_tolerance));
    in->filter->registerCallback(boost::function<void(const LaserScan::ConstPtr&)>(
        [this, raw](const LaserScan::ConstPtr& scan) { onTransformable(raw, scan); }));
    in->filter->registerFailureCallback(
        boost::function<void(const LaserScan::ConstPtr&,
                             tf2_ros::filter_failure_reasons::FilterFailureReason)>(
            [this, raw](const LaserScan::ConstPtr&,
                        tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
              onFilterFailure(raw, reason);
            }));
    in->sub = nh_.subscribe<LaserScan>(
        ic.topic, kSubscriberQueue,
        boost::function<void(const LaserScan::ConstPtr&)>(
            [this, raw](const LaserScan::ConstPtr& scan) { onScan(raw, scan); }),
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
    updater_->add(
        in->topic + " input",
        [this, raw](diagnostic_updater::DiagnosticStatusWrapper& s) { diagnoseInput(raw, s); });
    if (ic.expected_rate > 0.0) {
      auto freq = std::make_unique<diagnostic_updater::FrequencyStatus>(
          diagnostic_updater::FrequencyStatusParam(&raw->min_freq, &raw->max_freq, 0.0, 5),
          in->topic + " rate");
      updater_->add(*freq);
      in->freq = freq.get();
      freq_.push_back(std::move(freq));
    }
    inputs_.push_back(std::move(in));
  }

  reset_srv_ = pnh_.advertiseService("reset", &Impl::onReset, this);
  clear_srv_ = pnh_.advertiseService("clear_region", &Impl::onClearRegion, this);
  save_srv_ = pnh_.advertiseService("save_map", &Impl::onSaveMap, this);

  // dynamic_reconfigure starts from the loaded configuration (not from the .cfg defaults, which
  // are only the "forget" policy's).
  reconfigure_ = std::make_unique<dynamic_reconfigure::Server<wavog_mapping::MappingConfig>>(
      reconfigure_mutex_, pnh_);
  wavog_mapping::MappingConfig rc;
  rc.gamma = config_.map.policy.gamma;
  rc.clamp_min = config_.map.policy.clamp_min;
  rc.clamp_max = config_.map.policy.clamp_max;
  rc.odd_occ = config_.map.sensor.odd_occ;
  rc.odd_emp = config_.map.sensor.odd_emp;
  rc.publish_rate = rp.publish_rate;
  rc.scales = joinScales(rp.publish_scales);
  reconfigure_->updateConfig(rc);
  reconfigure_->setCallback(
      [this](wavog_mapping::MappingConfig& c, std::uint32_t level) { onReconfigure(c, level); });

  last_status_time_ = ros::Time::now();
  publish_timer_ =
      nh_.createTimer(ros::Duration(1.0 / rp.publish_rate), &Impl::onPublishTimer, this);
  if (rp.update_rate > 0.0) {
    update_timer_ =
        nh_.createTimer(ros::Duration(1.0 / rp.update_rate), &Impl::onUpdateTimer, this);
  }
  diag_timer_ =
      nh_.createTimer(ros::Duration(0.5), [this](const ros::TimerEvent&) { updater_->update(); });

  std::string topics;
  for (const auto& in : inputs_) topics += " " + in->topic;
  ROS_INFO("%s: mapping%s into '%s' (policy %s, resolution %g m), publishing at %g Hz",
           pnh_.getNamespace().c_str(), topics.c_str(), rp.map_frame.c_str(),
           wavog::toString(config_.map.policy.type), config_.map.grid.resolution, rp.publish_rate);
}

MappingRos::Impl::~Impl() {
  publish_timer_.stop();
  update_timer_.stop();
  diag_timer_.stop();
  tf_sub_.shutdown();
  tf_static_sub_.shutdown();
  for (auto& in : inputs_) in->sub.shutdown();
  reconfigure_.reset();
  inputs_.clear();  // filters before the buffer
}

void MappingRos::Impl::warnLocked(Input* in, std::size_t slot, const std::string& text) {
  const ros::WallTime now = ros::WallTime::now();
  if (!in->last_warn[slot].isZero() && (now - in->last_warn[slot]).toSec() < kWarnPeriod) return;
  in->last_warn[slot] = now;
  ROS_WARN("%s: %s", in->topic.c_str(), text.c_str());
}

void MappingRos::Impl::dropLocked(Input* in, DropReason reason, const std::string& detail) {
  const auto r = static_cast<std::size_t>(reason);
  const std::uint64_t n = ++in->c.dropped[r];
  warnLocked(in, r,
             "scan dropped (" + std::string(toString(reason)) + ", " + std::to_string(n) +
                 " so far): " + detail);
}

void MappingRos::Impl::onScan(Input* in, const LaserScan::ConstPtr& scan) {
  if (in->freq) in->freq->tick();  // FrequencyStatus locks itself
  const ros::Time now = ros::Time::now();
  bool clear_tf = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++in->c.received;
    ++in->c.received_in_period;
    in->c.last_receipt = now;
    // The clock jumping backwards (a bag restarted with --clock): the tf buffer holds the old
    // future and would refuse every new scan, so clear it and go on.
    if (!last_now_.isZero() && (last_now_ - now).toSec() > kTimeJumpThreshold) {
      ++clock_jumps_;
      clear_tf = true;
    }
    last_now_ = now;
    // Stamps jumping backwards on one input (a bag restarted without --clock, a driver reset):
    // counted and warned; such a scan is placed by tf if its stamp is still in the buffer, else
    // dropped as too old.
    if (!in->c.last_received_stamp.isZero() &&
        (in->c.last_received_stamp - scan->header.stamp).toSec() > kTimeJumpThreshold) {
      ++in->c.time_jumps;
      warnLocked(in, kNumDropReasons,
                 "stamp jumped backwards by " +
                     std::to_string((in->c.last_received_stamp - scan->header.stamp).toSec()) +
                     " s");
    }
    in->c.last_received_stamp = scan->header.stamp;
    DropReason reason{};
    if (!checkScan(*scan, &reason)) {
      std::ostringstream detail;
      detail << "frame_id '" << scan->header.frame_id << "', " << scan->ranges.size()
             << " ranges, angles [" << scan->angle_min << ", " << scan->angle_max << "] step "
             << scan->angle_increment;
      dropLocked(in, reason, detail.str());
      return;
    }
  }
  std::lock_guard<std::mutex> tf_lock(tf_mutex_);
  if (clear_tf) {
    ROS_WARN("%s: clock jumped backwards: tf buffer cleared", pnh_.getNamespace().c_str());
    buffer_->clear();
  }
  in->filter->add(scan);
}

void MappingRos::Impl::onTf(const tf2_msgs::TFMessage::ConstPtr& msg, bool is_static) {
  std::lock_guard<std::mutex> tf_lock(tf_mutex_);
  for (const auto& t : msg->transforms) {
    try {
      buffer_->setTransform(t, "default_authority", is_static);
    } catch (const tf2::TransformException& e) {
      ROS_WARN_THROTTLE(kWarnPeriod, "%s: transform refused by the tf buffer: %s",
                        pnh_.getNamespace().c_str(), e.what());
    }
  }
}

void MappingRos::Impl::onFilterFailure(
    Input* in, tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  switch (reason) {
    case tf2_ros::filter_failure_reasons::OutTheBack:
      dropLocked(in, DropReason::kTfTooOld, "stamp older than the tf buffer");
      break;
    case tf2_ros::filter_failure_reasons::EmptyFrameID:
      dropLocked(in, DropReason::kBadFrame, "empty frame_id");
      break;
    default:
      dropLocked(in, DropReason::kTfUnavailable,
                 "no transform to '" + config_.ros.map_frame + "' (unknown frame or tf late)");
      break;
  }
}

void MappingRos::Impl::onTransformable(Input* in, const LaserScan::ConstPtr& scan) {
  const std::string& map_frame = config_.ros.map_frame;  // constant after construction
  const std::string& frame = scan->header.frame_id;
  geometry_msgs::TransformStamped start;
  try {
    start = buffer_->lookupTransform(map_frame, frame, scan->header.stamp);
  } catch (const tf2::TransformException& e) {
    std::lock_guard<std::mutex> lock(mutex_);
    dropLocked(in, DropReason::kTfUnavailable, e.what());
    return;
  }
  bool mirrored = false;
  const wavog::Pose2 pose0 = toPose2(start.transform, &mirrored);
  wavog::Pose2 pose1 = pose0;

  // Motion compensation: two lookups per scan (first and last beam), never one per beam.
  const std::size_t n = scan->ranges.size();
  bool compensate = config_.ros.motion_compensation && n > 1 &&
                    std::isfinite(scan->time_increment) && scan->time_increment != 0.0f;
  bool fallback = false;
  if (compensate) {
    const double sweep = static_cast<double>(scan->time_increment) * static_cast<double>(n - 1);
    try {
      bool mirrored_end = false;
      pose1 = toPose2(
          buffer_->lookupTransform(map_frame, frame, scan->header.stamp + ros::Duration(sweep))
              .transform,
          &mirrored_end);
    } catch (const tf2::TransformException&) {
      compensate = false;
      fallback = true;
    }
  }

  wavog::ScanView view = toScanView(*scan);
  if (mirrored) mirrorView(&view);

  std::lock_guard<std::mutex> lock(mutex_);
  if (fallback) {
    ++in->c.motion_fallbacks;
    warnLocked(in, kNumDropReasons, "no tf at the end of the sweep: motion compensation skipped");
  }
  wavog::Pose2 pose = pose0;
  if (compensate) {
    pose = wavog::interpolate(pose0, pose1, 0.5);
    view = compensator_.compensate(view, pose0, pose1, pose);
  }
  const auto t0 = Clock::now();
  const wavog::IntegrateStats st = map_.integrate(pose, view);
  const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
  integrate_time_sum_ += dt;
  integrate_time_max_ = std::max(integrate_time_max_, dt);
  ++integrate_count_;
  in->c.beams_invalid += st.beams_invalid;
  in->c.beams_no_return += st.beams_no_return;
  switch (st.status) {
    case wavog::ScanStatus::kOk: {
      ++in->c.integrated;
      in->c.last_stamp = scan->header.stamp;
      const double reach = wavog::scanReach(view, map_.params().sensor, map_.resolution());
      if (!dirty_) {
        dirty_min_x_ = dirty_max_x_ = pose.x;
        dirty_min_y_ = dirty_max_y_ = pose.y;
        dirty_ = true;
      }
      dirty_min_x_ = std::min(dirty_min_x_, pose.x - reach);
      dirty_min_y_ = std::min(dirty_min_y_, pose.y - reach);
      dirty_max_x_ = std::max(dirty_max_x_, pose.x + reach);
      dirty_max_y_ = std::max(dirty_max_y_, pose.y + reach);
      break;
    }
    case wavog::ScanStatus::kEmpty:
      dropLocked(in, DropReason::kEmpty, "no beams");
      break;
    case wavog::ScanStatus::kNoValidBeam:
      dropLocked(in, DropReason::kNoValidBeam, "every beam is NaN, -inf or below range_min");
      break;
    case wavog::ScanStatus::kBadGeometry:
    case wavog::ScanStatus::kBadPose:
      dropLocked(in, DropReason::kBadGeometry,
                 std::string("refused by the core: ") + wavog::toString(st.status));
      break;
  }
}

void MappingRos::Impl::advertiseScalesLocked(const std::vector<int>& scales) {
  std::map<int, ros::Publisher> pubs;
  for (int s : scales) {
    auto it = scale_pubs_.find(s);
    pubs[s] = it != scale_pubs_.end()
                  ? it->second
                  : nh_.advertise<nav_msgs::OccupancyGrid>("map_scale_" + std::to_string(s), 1);
  }
  scale_pubs_.swap(pubs);
}

void MappingRos::Impl::markAllDirtyLocked() {
  // The next map_updates carries the whole last full grid.
  if (!have_full_) return;
  const double res = map_.resolution();
  dirty_ = true;
  dirty_min_x_ = static_cast<double>(last_full_box_.min_x) * res;
  dirty_min_y_ = static_cast<double>(last_full_box_.min_y) * res;
  dirty_max_x_ = static_cast<double>(last_full_box_.max_x) * res;
  dirty_max_y_ = static_cast<double>(last_full_box_.max_y) * res;
}

void MappingRos::Impl::onPublishTimer(const ros::TimerEvent&) {
  const auto t_start = Clock::now();
  const ros::Time now = ros::Time::now();
  const RosParams& rp = config_.ros;

  // Window centre: the robot, from tf (latest), outside the lock.
  bool windowed = rp.publish_window > 0.0;
  double cx = 0.0, cy = 0.0;
  bool window_ok = true;
  if (windowed) {
    try {
      const auto t = buffer_->lookupTransform(rp.map_frame, rp.base_frame, ros::Time(0));
      cx = t.transform.translation.x;
      cy = t.transform.translation.y;
    } catch (const tf2::TransformException& e) {
      window_ok = false;
      ROS_WARN_THROTTLE(kWarnPeriod,
                        "%s: no pose of '%s' for publish_window, maps not published: %s",
                        pnh_.getNamespace().c_str(), rp.base_frame.c_str(), e.what());
    }
  }

  struct Job {
    int scale;
    ros::Publisher pub;
    wavog::Raster raster;
  };
  std::vector<Job> jobs;
  auto status = boost::make_shared<wavog_mapping::MapperStatus>();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (window_ok) {
      // `map` is latched: always published. A scale layer nobody listens to costs nothing.
      jobs.push_back({0, map_pub_, {}});
      for (const auto& sp : scale_pubs_) {
        if (sp.second.getNumSubscribers() > 0) jobs.push_back({sp.first, sp.second, {}});
      }
    }
    for (Job& job : jobs) {
      // With a window, the read-out costs what the window holds, never the whole map.
      wavog::CellBox box;
      bool have = true;
      if (windowed) {
        const double w = rp.publish_window;
        box = map_.boxAround(cx - w, cy - w, cx + w, cy + w, job.scale);
      } else {
        have = map_.bounds(job.scale, &box);
      }
      job.raster =
          have && !box.empty()
              ? map_.exportScale(job.scale, box,
                                 job.scale == 0 ? wavog::Aggregation::kMean : rp.scale_aggregation)
              : emptyRaster(job.scale, map_.resolution());
      if (job.scale == 0) {
        // The dirty region is reset by map_updates only: re-sending an area the full map already
        // carries is harmless, while two timers of the same period would otherwise starve updates.
        have_full_ = true;
        last_full_box_ = job.raster.box;
      }
    }

    // Status of the period that ends now.
    const double period = (now - last_status_time_).toSec();
    last_status_time_ = now;
    status->header.stamp = now;
    status->header.frame_id = rp.map_frame;
    for (const auto& in : inputs_) {
      InputCounters& c = in->c;
      c.rate = period > 0.0 ? static_cast<double>(c.received_in_period) / period : 0.0;
      c.received_in_period = 0;
      wavog_mapping::InputStatus s;
      s.topic = in->topic;
      s.received = c.received;
      s.integrated = c.integrated;
      const auto d = [&c](DropReason r) { return c.dropped[static_cast<std::size_t>(r)]; };
      s.dropped_empty = d(DropReason::kEmpty);
      s.dropped_size_mismatch = d(DropReason::kSizeMismatch);
      s.dropped_bad_angles = d(DropReason::kBadAngles);
      s.dropped_bad_frame = d(DropReason::kBadFrame);
      s.dropped_tf_unavailable = d(DropReason::kTfUnavailable);
      s.dropped_tf_too_old = d(DropReason::kTfTooOld);
      s.dropped_no_valid_beam = d(DropReason::kNoValidBeam);
      s.dropped_bad_geometry = d(DropReason::kBadGeometry);
      s.time_jumps = c.time_jumps;
      s.motion_fallbacks = c.motion_fallbacks;
      s.beams_invalid = c.beams_invalid;
      s.beams_no_return = c.beams_no_return;
      s.last_stamp = c.last_stamp;
      s.rate = c.rate;
      s.expected_rate = in->config.expected_rate;
      status->scans_integrated += c.integrated;
      status->tf_failures += s.dropped_tf_unavailable + s.dropped_tf_too_old;
      status->clock_jumps = clock_jumps_;
      status->inputs.push_back(s);
    }
    last_mean_ =
        integrate_count_ > 0 ? integrate_time_sum_ / static_cast<double>(integrate_count_) : 0.0;
    last_max_ = integrate_time_max_;
    status->integrate_time_mean = last_mean_;
    status->integrate_time_max = last_max_;
    integrate_time_sum_ = integrate_time_max_ = 0.0;
    integrate_count_ = 0;
    status->publish_time = publish_time_;
    const wavog::MapStats ms = map_.stats();
    status->blocks = ms.blocks;
    status->nodes = ms.nodes;
    status->bytes = ms.bytes;
  }

  for (const Job& job : jobs) job.pub.publish(toOccupancyGridMsg(job.raster, rp.map_frame, now));
  status_pub_.publish(status);
  const double elapsed = std::chrono::duration<double>(Clock::now() - t_start).count();
  std::lock_guard<std::mutex> lock(mutex_);
  publish_time_ = elapsed;
}

void MappingRos::Impl::onUpdateTimer(const ros::TimerEvent&) {
  if (update_pub_.getNumSubscribers() == 0) return;
  const ros::Time now = ros::Time::now();
  wavog::Raster raster;
  wavog::CellBox full;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!dirty_ || !have_full_) return;
    full = last_full_box_;
    wavog::CellBox box = map_.boxAround(dirty_min_x_, dirty_min_y_, dirty_max_x_, dirty_max_y_, 0);
    box.min_x = std::max(box.min_x, full.min_x);
    box.min_y = std::max(box.min_y, full.min_y);
    box.max_x = std::min(box.max_x, full.max_x);
    box.max_y = std::min(box.max_y, full.max_y);
    dirty_ = false;
    if (box.empty()) return;
    raster = map_.exportScale(0, box, wavog::Aggregation::kMean);
  }
  update_pub_.publish(
      toOccupancyGridUpdateMsg(raster, full.min_x, full.min_y, config_.ros.map_frame, now));
}

bool MappingRos::Impl::onReset(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  std::lock_guard<std::mutex> lock(mutex_);
  map_.reset();
  markAllDirtyLocked();
  ROS_INFO("%s: map reset", pnh_.getNamespace().c_str());
  return true;
}

bool MappingRos::Impl::onClearRegion(wavog_mapping::ClearRegion::Request& req,
                                     wavog_mapping::ClearRegion::Response& res) {
  if (!(std::isfinite(req.min_x) && std::isfinite(req.min_y) && std::isfinite(req.max_x) &&
        std::isfinite(req.max_y) && req.min_x <= req.max_x && req.min_y <= req.max_y)) {
    res.success = false;
    res.message = "the box must be finite with min <= max";
    return true;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  map_.clearBox(req.min_x, req.min_y, req.max_x, req.max_y);
  if (!dirty_) {
    dirty_ = true;
    dirty_min_x_ = req.min_x;
    dirty_min_y_ = req.min_y;
    dirty_max_x_ = req.max_x;
    dirty_max_y_ = req.max_y;
  } else {
    dirty_min_x_ = std::min(dirty_min_x_, req.min_x);
    dirty_min_y_ = std::min(dirty_min_y_, req.min_y);
    dirty_max_x_ = std::max(dirty_max_x_, req.max_x);
    dirty_max_y_ = std::max(dirty_max_y_, req.max_y);
  }
  res.success = true;
  res.message = "cleared";
  return true;
}

bool MappingRos::Impl::onSaveMap(wavog_mapping::SaveMap::Request& req,
                                 wavog_mapping::SaveMap::Response& res) {
  if (req.path.empty()) {
    res.success = false;
    res.message = "path is empty";
    return true;
  }
  // <stem>: the path without its extension; images go beside the map file.
  const std::size_t slash = req.path.find_last_of('/');
  const std::size_t dot = req.path.find_last_of('.');
  const std::string stem = (dot != std::string::npos && (slash == std::string::npos || dot > slash))
                               ? req.path.substr(0, dot)
                               : req.path;
  std::vector<wavog::Raster> rasters;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    try {
      map_.save(req.path);
    } catch (const wavog::MapIoError& e) {
      res.success = false;
      res.message = e.what();
      return true;
    }
    std::vector<int> scales = {0};
    for (const auto& sp : scale_pubs_) scales.push_back(sp.first);
    for (int s : scales) {
      wavog::CellBox box;
      if (map_.bounds(s, &box) && !box.empty()) {
        rasters.push_back(map_.exportScale(
            s, box, s == 0 ? wavog::Aggregation::kMean : config_.ros.scale_aggregation));
      }
    }
  }
  res.files.push_back(req.path);
  try {
    for (const wavog::Raster& r : rasters) {
      const std::string base = stem + "_scale_" + std::to_string(r.scale);
      res.files.push_back(base + ".pgm");
      res.files.push_back(wavog::writeMapServerMap(base, r));
    }
  } catch (const std::exception& e) {
    res.success = false;
    res.message = e.what();
    return true;
  }
  res.success = true;
  res.message = "saved " + std::to_string(res.files.size()) + " files";
  ROS_INFO("%s: map saved to %s (+ %zu map_server images)", pnh_.getNamespace().c_str(),
           req.path.c_str(), rasters.size());
  return true;
}

void MappingRos::Impl::onReconfigure(wavog_mapping::MappingConfig& rc, std::uint32_t) {
  // The timer is re-armed after the lock is released (roscpp's timer manager has locks of its own).
  double new_period = 0.0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    wavog::MapParams next = config_.map;
    next.policy.gamma = rc.gamma;
    next.policy.clamp_min = rc.clamp_min;
    next.policy.clamp_max = rc.clamp_max;
    next.sensor.odd_occ = rc.odd_occ;
    next.sensor.odd_emp = rc.odd_emp;
    RosParams next_ros = config_.ros;
    next_ros.publish_rate = rc.publish_rate;
    std::vector<std::string> errors;
    if (!parseScales(rc.scales, &next_ros.publish_scales)) {
      errors.push_back("scales ('" + rc.scales + "') must be comma-separated integers");
    }
    for (const auto& e : next.validate()) errors.push_back(e);
    for (const auto& e : validate(next_ros, next)) errors.push_back(e);
    if (errors.empty()) {
      try {
        map_.setPolicy(next.policy, next.sensor);
      } catch (const std::invalid_argument& e) {
        errors.emplace_back(e.what());
      }
    }
    if (!errors.empty()) {
      std::string text;
      for (const auto& e : errors) text += "\n  " + e;
      ROS_ERROR("%s: reconfiguration refused, keeping the previous values:%s",
                pnh_.getNamespace().c_str(), text.c_str());
      // Hand the previous values back to the reconfigure server (and its clients).
      rc.gamma = config_.map.policy.gamma;
      rc.clamp_min = config_.map.policy.clamp_min;
      rc.clamp_max = config_.map.policy.clamp_max;
      rc.odd_occ = config_.map.sensor.odd_occ;
      rc.odd_emp = config_.map.sensor.odd_emp;
      rc.publish_rate = config_.ros.publish_rate;
      rc.scales = joinScales(config_.ros.publish_scales);
      return;
    }
    if (next_ros.publish_rate != config_.ros.publish_rate) new_period = 1.0 / next_ros.publish_rate;
    config_.map = next;
    config_.ros.publish_rate = next_ros.publish_rate;
    config_.ros.publish_scales = next_ros.publish_scales;
    advertiseScalesLocked(next_ros.publish_scales);
  }
  if (new_period > 0.0) publish_timer_.setPeriod(ros::Duration(new_period));
}

void MappingRos::Impl::diagnoseInput(const Input* in,
                                     diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::lock_guard<std::mutex> lock(mutex_);
  const InputCounters& c = in->c;
  const ros::Time now = ros::Time::now();
  // Stale: nothing for 5 expected periods (or 5 s when no rate is expected).
  const double stale_after = in->config.expected_rate > 0.0 ? 5.0 / in->config.expected_rate : 5.0;
  std::uint64_t dropped = 0;
  for (auto d : c.dropped) dropped += d;
  if (c.received == 0) {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no scan received yet");
  } else if ((now - c.last_receipt).toSec() > std::max(stale_after, 0.5)) {
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN, "stale: no scan for %.1f s",
                  (now - c.last_receipt).toSec());
  } else if (c.integrated == 0) {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "scans received but none integrated");
  } else {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "integrating");
  }
  stat.add("received", c.received);
  stat.add("integrated", c.integrated);
  stat.add("dropped", dropped);
  for (std::size_t r = 0; r < kNumDropReasons; ++r) {
    stat.add(std::string("dropped ") + toString(static_cast<DropReason>(r)), c.dropped[r]);
  }
  stat.add("time jumps", c.time_jumps);
  stat.add("measured rate (Hz)", c.rate);
  stat.add("expected rate (Hz)", in->config.expected_rate);
}

void MappingRos::Impl::diagnoseMapper(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::uint64_t tf_failures = 0;
  double expected_total = 0.0;
  for (const auto& in : inputs_) {
    tf_failures += in->c.dropped[static_cast<std::size_t>(DropReason::kTfUnavailable)] +
                   in->c.dropped[static_cast<std::size_t>(DropReason::kTfTooOld)];
    expected_total += in->config.expected_rate;
  }
  const std::uint64_t new_failures = tf_failures - tf_failures_reported_;
  tf_failures_reported_ = tf_failures;
  if (new_failures > 0) {
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN, "%llu tf failures since last report",
                  static_cast<unsigned long long>(new_failures));
  } else if (expected_total > 0.0 && last_mean_ * expected_total > 0.8) {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                 "integration cannot keep up with the expected scan rate");
  } else {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "ok");
  }
  stat.add("tf failures", tf_failures);
  stat.add("clock jumps", clock_jumps_);
  stat.add("integration time mean (s)", last_mean_);
  stat.add("integration time max (s)", last_max_);
  stat.add("publish time (s)", publish_time_);
  const wavog::MapStats ms = map_.stats();
  stat.add("blocks", ms.blocks);
  stat.add("nodes", ms.nodes);
  stat.add("bytes", ms.bytes);
}

MappingRos::MappingRos(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
    : impl_(std::make_unique<Impl>(nh, pnh)) {}

MappingRos::~MappingRos() = default;

}  // namespace wavog_ros
