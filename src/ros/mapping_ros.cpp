// MappingRos (see mapping_ros.h): construction and tear-down. Loads the configuration, connects
// tf, the inputs, the publishers, the services, dynamic_reconfigure and the timers; the callbacks
// they lead to live in the files named in mapping_ros_impl.h.
#include "wavog_mapping/ros/mapping_ros.h"

#include <algorithm>
#include <stdexcept>

#include "checked_subscription.h"
#include "fleet/fleet_receiver.h"
#include "fleet/fleet_stream.h"
#include "fleet/vehicle_windows.h"
#include "mapping_ros_impl.h"
#include "reconfigure.h"

namespace wavog_ros {
namespace {

/// Smallest /tf and /tf_static subscriber queue (the size roscpp's TransformListener uses).
constexpr int kMinTfQueue = 100;
/// Period (s) of the /diagnostics updater.
constexpr double kDiagnosticsPeriod = 1.0;

Config loadReportingUnknown(const ros::NodeHandle& pnh) {
  std::vector<std::string> unknown;
  Config c = loadConfig(pnh, &unknown);
  for (const auto& key : unknown) {
    ROS_WARN("%s: unknown parameter '%s' ignored (config/default.yaml lists every key)",
             pnh.getNamespace().c_str(), key.c_str());
  }
  for (const auto& w : c.map.warnings()) ROS_WARN("%s: %s", pnh.getNamespace().c_str(), w.c_str());
  return c;
}

}  // namespace

void MappingRos::Impl::warnDroppedPayloads(const std::string& path) const {
  const wavog::MapFileContents held = wavog::WaveletMap::inspectFile(path);
  const auto warn = [&](const char* what, const char* key) {
    ROS_WARN(
        "%s: map_file '%s' holds %s, which this mapper drops (%s: false): a later save_map "
        "writes the map without it; set %s: true to keep it",
        pnh_.getNamespace().c_str(), path.c_str(), what, key, key);
  };
  if (held.reflection && !config_.map.reflection) warn("a reflection map", "reflection");
  if (held.ndt && !config_.map.ndt) warn("normal-distribution (NDT) cells", "ndt");
}

MappingRos::Impl::Impl(const ros::NodeHandle& nh, const ros::NodeHandle& pnh, MapperRole role)
    : nh_(nh), pnh_(pnh), config_(loadReportingUnknown(pnh)), map_(config_.map) {
  const RosParams& rp = config_.ros;
  if (role == MapperRole::kMapper) {  // in this namespace, with the node's remappings
    const std::string duplicate = duplicateInputs(
        rp.inputs, [this](const std::string& topic) { return nh_.resolveName(topic); });
    if (!duplicate.empty()) throw std::invalid_argument("invalid configuration: " + duplicate);
  }
  placement_.fixed_frame = rp.map_frame;
  placement_.motion_compensation = rp.motion_compensation;
  if (!rp.map_file.empty()) {
    try {
      map_.load(rp.map_file);
    } catch (const std::exception& e) {  // MapIoError (not a regular file, corrupt, ...) or else
      throw std::runtime_error("map_file: cannot load '" + rp.map_file + "': " + e.what());
    }
    ROS_INFO("%s: loaded map_file '%s'", pnh_.getNamespace().c_str(), rp.map_file.c_str());
    warnDroppedPayloads(rp.map_file);
  }
  if (role == MapperRole::kMapper) subscribeTf();

  publisher_ = std::make_unique<MapPublisher>(nh_, rp.publish_scales, config_.map.reflection,
                                              config_.map.ndt);  // not yet shared: no lock
  // Latched: the last status stays readable after a bag ends (its /clock, and so the publish
  // timer, stops with it; the end of the input publishes it once more).
  status_pub_ = pnh_.advertise<wavog_mapping::MapperStatus>("status", 10, true);
  updater_ = std::make_unique<diagnostic_updater::Updater>(nh_, pnh_, pnh_.getNamespace());
  updater_->setHardwareID("wavog_mapping");
  updater_->add("mapper",
                [this](diagnostic_updater::DiagnosticStatusWrapper& s) { diagnoseMapper(s); });
  if (role == MapperRole::kMapper) {
    for (const InputConfig& ic : rp.inputs) addInput(ic);
  }
  startFleet(role);

  advertiseServices();
  startReconfigure();
  startTimers();

  std::string topics;
  for (const auto& in : inputs_) topics += " " + in->topic;
  for (const auto& v : rp.fleet_vehicles) {
    if (role == MapperRole::kFleet) topics += " " + v + "/fleet_scans";
  }
  ROS_INFO("%s: mapping%s into '%s' (policy %s, resolution %g m), publishing at %g Hz",
           pnh_.getNamespace().c_str(), topics.c_str(), rp.map_frame.c_str(),
           wavog::toString(config_.map.policy.type), config_.map.grid.resolution, rp.publish_rate);
}

MappingRos::Impl::~Impl() {
  publish_timer_.stop();
  update_timer_.stop();
  diag_timer_.stop();
  idle_timer_.stop();
  silent_timer_.stop();
  retry_timer_.stop();
  tf_sub_.shutdown();
  tf_static_sub_.shutdown();
  for (auto& in : inputs_) in->sub.shutdown();
  reconfigure_.reset();
  fleet_.reset();
  fleet_stream_.reset();
  inputs_.clear();  // filters before the buffer
}

void MappingRos::Impl::subscribeTf() {
  buffer_ = std::make_unique<tf2_ros::Buffer>(ros::Duration(config_.ros.tf_cache_time));
  ros::NodeHandle root;
  // As deep as the scans' queues: when the node stalls, roscpp would otherwise drop the oldest tf
  // and hand the queued scans a buffer that has moved on (they would be dropped as tf too old).
  const auto queue =
      static_cast<std::uint32_t>(std::max(kMinTfQueue, config_.ros.subscriber_queue_size));
  for (const bool is_static : {false, true}) {
    (is_static ? tf_static_sub_ : tf_sub_) = root.subscribe<tf2_msgs::TFMessage>(
        is_static ? "/tf_static" : "/tf", queue,
        boost::function<void(const tf2_msgs::TFMessage::ConstPtr&)>(
            [this, is_static](const tf2_msgs::TFMessage::ConstPtr& m) {
              guarded("tf callback", nullptr, [&] { onTf(m, is_static); });
            }),
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  }
}

void MappingRos::Impl::addInput(const InputConfig& ic) {
  using FailureReason = tf2_ros::filter_failure_reasons::FilterFailureReason;
  using LaserScan = sensor_msgs::LaserScan;
  const RosParams& rp = config_.ros;
  auto in = std::make_unique<Input>();
  in->config = ic;
  in->topic = nh_.resolveName(ic.topic);
  in->min_freq = ic.expected_rate * (1.0 - rp.rate_tolerance);
  in->max_freq = ic.expected_rate * (1.0 + rp.rate_tolerance);
  in->poses = PoseCheck(rp.max_sensor_speed);
  Input* raw = in.get();
  // subscriber -> onScan (checks) -> tf filter -> onTransformable (placement, core).
  in->filter = std::make_unique<ScanFilter>(*buffer_, rp.map_frame,
                                            static_cast<std::uint32_t>(rp.queue_size), nh_);
  in->filter->setTolerance(ros::Duration(rp.tf_tolerance));
  in->filter->registerCallback(boost::function<void(const LaserScan::ConstPtr&)>(
      [this, raw](const LaserScan::ConstPtr& scan) {
        guarded("scan integration", raw, [&] { onTransformable(raw, scan); });
      }));
  in->filter->registerFailureCallback(
      boost::function<void(const LaserScan::ConstPtr&, FailureReason)>(
          [this, raw](const LaserScan::ConstPtr& scan, FailureReason reason) {
            guarded("tf filter failure callback", nullptr,
                    [&] { onFilterFailure(raw, scan, reason); });
          }));
  // The subscriber queue (subscriber_queue_size) holds bursts (several drivers on one host, fast
  // playback) until onScan runs; roscpp drops its oldest scan silently when it is full, which
  // onScan counts from the gaps in header.seq per connection (the event's connection header,
  // by address only: MessageEvent::getPublisherName() uses the map's operator[], which
  // ThreadSanitizer shows racing with roscpp dropping the connection).
  // Deserialised with every array length checked against the message's bytes first (issue 42):
  // a forged length prefix is counted as bad_length instead of sizing ranges to it.
  in->sub = subscribeChecked<LaserScan>(
      nh_, ic.topic, static_cast<std::uint32_t>(rp.subscriber_queue_size),
      boost::function<void(const ros::MessageEvent<const LaserScan>&)>(
          [this, raw](const ros::MessageEvent<const LaserScan>& event) {
            guarded("scan callback", raw, [&] {
              onScan(raw, event.getConstMessage(),
                     reinterpret_cast<std::uintptr_t>(event.getConnectionHeaderPtr().get()));
            });
          }),
      [this, raw](const LaserScan& partial, const Refused& r) {
        guarded("scan deserialisation", nullptr, [&] { onRefusedScan(raw, partial, r); });
      });
  updater_->add(in->topic + " input", [this, raw](diagnostic_updater::DiagnosticStatusWrapper& s) {
    diagnoseInput(raw, s);
  });
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

void MappingRos::Impl::startReconfigure() {
  // The server starts from the loaded configuration (not from the .cfg defaults, which are only
  // the "forget" policy's).
  reconfigure_ = std::make_unique<ReconfigureServer>(
      pnh_, toReconfigure(config_), [this](const wavog_mapping::MappingConfig& rc) {
        std::vector<std::string> errors = {"internal error (logged)"};
        guarded("reconfigure callback", nullptr, [&] { errors = onReconfigure(rc); });
        return errors;
      });
}

void MappingRos::Impl::startTimers() {
  const RosParams& rp = config_.ros;
  last_status_time_ = ros::Time::now();
  // Outputs run on wall time: with use_sim_time the clock stops with the bag, and ROS timers
  // with it, while users still echo the layers, the status and /diagnostics.
  publish_timer_ = nh_.createWallTimer(
      ros::WallDuration(1.0 / rp.publish_rate), [this](const ros::WallTimerEvent& e) {
        guarded("publish timer", nullptr, [&] { onPublishTimer(e); });
      });
  if (rp.update_rate > 0.0) {
    update_timer_ = nh_.createWallTimer(
        ros::WallDuration(1.0 / rp.update_rate), [this](const ros::WallTimerEvent& e) {
          guarded("update timer", nullptr, [&] { onUpdateTimer(e); });
        });
  }
  // force_update(): update() waits for the (stopped) ROS clock to pass its period.
  diag_timer_ = nh_.createWallTimer(
      ros::WallDuration(kDiagnosticsPeriod), [this](const ros::WallTimerEvent&) {
        guarded("diagnostics timer", nullptr, [&] { updater_->force_update(); });
      });
  if (!inputs_.empty()) {
    // Wall time: a bag on other topics may be what drives /clock, or nothing does.
    silent_timer_ = nh_.createWallTimer(
        ros::WallDuration(kSilentInputPeriod), [this](const ros::WallTimerEvent&) {
          guarded("silent input timer", nullptr, [&] { warnSilentInputs(); });
        });
    // Wall time, as the tf that places the waiting scans may come with the ROS clock stopped.
    retry_timer_ =
        nh_.createWallTimer(ros::WallDuration(kRetryPeriod), [this](const ros::WallTimerEvent& e) {
          guarded("tf retry timer", nullptr, [&] { onRetryTimer(e); });
        });
  }
  if (rp.idle_timeout > 0.0) {
    // Wall time: with use_sim_time the clock stops with the bag, and ROS timers with it.
    noteActivity();
    idle_timer_ = nh_.createWallTimer(ros::WallDuration(std::min(0.25, rp.idle_timeout / 4.0)),
                                      [this](const ros::WallTimerEvent& e) {
                                        guarded("idle timer", nullptr, [&] { onIdleTimer(e); });
                                      });
  }
}

std::vector<std::string> MappingRos::Impl::onReconfigure(const wavog_mapping::MappingConfig& rc) {
  // The timer is re-armed after the lock is released (roscpp's timer manager has locks of its own).
  double new_period = 0.0;
  std::vector<std::string> errors;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const Config next = withReconfigure(config_, rc, &errors);
    if (errors.empty()) {
      try {
        map_.setPolicy(next.map.policy, next.map.sensor);  // applies pending forgetting first
      } catch (const std::invalid_argument& e) {
        errors.emplace_back(e.what());
      }
    }
    if (!errors.empty()) return errors;  // the server logs them and answers the values in force
    if (next.map.policy.type != config_.map.policy.type ||
        next.map.policy.init != config_.map.policy.init) {
      ROS_INFO("%s: policy %s, init %s from now on", pnh_.getNamespace().c_str(),
               wavog::toString(next.map.policy.type), wavog::toString(next.map.policy.init));
    }
    if (config_.map.reflection && (next.map.policy.type != config_.map.policy.type ||
                                   next.map.initValue() != config_.map.initValue() ||
                                   next.map.sensor.odd_occ != config_.map.sensor.odd_occ ||
                                   next.map.sensor.odd_emp != config_.map.sensor.odd_emp)) {
      ROS_INFO(
          "%s: the reflection map restarts from no hits and misses (policy, prior or odd "
          "values changed)",
          pnh_.getNamespace().c_str());
    }
    // A policy change can make a silent combination (MapParams::warnings) or end one.
    const std::vector<std::string> before = config_.map.warnings();
    for (const auto& w : next.map.warnings()) {
      if (std::find(before.begin(), before.end(), w) == before.end()) {
        ROS_WARN("%s: %s", pnh_.getNamespace().c_str(), w.c_str());
      }
    }
    if (next.ros.publish_rate != config_.ros.publish_rate) new_period = 1.0 / next.ros.publish_rate;
    // Only the run-time fields: the others (frames, ...) are read without the lock.
    config_.map = next.map;
    config_.ros.publish_rate = next.ros.publish_rate;
    config_.ros.publish_scales = next.ros.publish_scales;
    config_.ros.grid_values = next.ros.grid_values;
    config_.ros.scale_aggregation = next.ros.scale_aggregation;
    publisher_->advertiseScales(next.ros.publish_scales);
  }
  if (new_period > 0.0) publish_timer_.setPeriod(ros::WallDuration(new_period));
  return errors;
}

MappingRos::MappingRos(const ros::NodeHandle& nh, const ros::NodeHandle& pnh, MapperRole role)
    : impl_(std::make_unique<Impl>(nh, pnh, role)) {}

MappingRos::~MappingRos() = default;

}  // namespace wavog_ros
