// FleetReceiver (see fleet_receiver.h): subscriptions, checks, the reorder buffer, per-vehicle
// counters, ~fleet_status and the per-vehicle diagnostics.
#include "fleet_receiver.h"

#include <algorithm>
#include <boost/make_shared.hpp>
#include <stdexcept>

#include "../checked_subscription.h"
#include "intake.h"
#include "wavog_mapping/ros/conversions.h"

namespace wavog_fleet {
namespace {

/// Period (wall s) of the release timer: the reorder wait is kept to within this.
constexpr double kReleasePeriod = 0.01;
/// Seconds between two warnings about one vehicle.
constexpr double kWarnPeriod = 5.0;
/// Messages roscpp holds per vehicle before the callback (4 lasers x 40 Hz for 10 s).
constexpr std::uint32_t kSubscriberQueue = 2000;

std::int64_t toNs(const ros::Time& t) { return static_cast<std::int64_t>(t.toNSec()); }

}  // namespace

struct FleetReceiver::Vehicle {
  int index = 0;
  std::string name;
  std::string topic;
  ros::Subscriber sub;
  wavog_mapping::VehicleStatus c;  ///< counters (topic, vehicle filled at start)
  ros::WallTime last_receipt;      ///< zero: nothing yet
  ros::WallTime last_warn;
  StreamIndex stream_index;  ///< PlacedScan.index sequence (lost, regressions, jumps)
  bool stale_reported = false;
  double lag_max_period = 0.0;
  ros::Time oldest_unpublished;  ///< stamp of the oldest scan integrated since the last layers
  double publish_lag_max_period = 0.0;
  bool has_position = false;  ///< x, y: the latest integrated scan's sensor position
  double x = 0.0, y = 0.0;
};

FleetReceiver::FleetReceiver(ros::NodeHandle nh, ros::NodeHandle pnh,
                             const wavog_ros::RosParams& ros, double resolution, std::mutex* mutex,
                             IntegrateFn integrate, diagnostic_updater::Updater* updater)
    : nh_(nh),
      pnh_(pnh),
      limits_{ros.map_frame, resolution, ros.fleet_max_stamp_offset},
      stale_timeout_(ros.fleet_stale_timeout),
      integrate_late_(ros.fleet_integrate_late),
      reorder_wait_(ros.fleet_reorder_wait),
      reorder_max_wait_(ros.fleet_reorder_max_wait),
      mutex_(mutex),
      integrate_(std::move(integrate)),
      buffer_(ros.fleet_reorder_wait, ros.fleet_reorder_max_wait,
              static_cast<std::size_t>(ros.fleet_max_buffered)),
      horizon_(ros.fleet_vehicles.size(), ros.fleet_stale_timeout) {
  if (ros.fleet_vehicles.empty()) {
    throw std::invalid_argument(
        "fleet_vehicles must list 1 to " + std::to_string(wavog_ros::kMaxFleetVehicles) +
        " vehicle namespaces for wavog_fleet (config/fleet.yaml)");
  }
  status_pub_ = pnh_.advertise<wavog_mapping::FleetStatus>("fleet_status", 10);
  for (const std::string& name : ros.fleet_vehicles) {
    auto v = std::make_unique<Vehicle>();
    v->index = static_cast<int>(vehicles_.size());
    v->name = name;
    v->topic = nh_.resolveName(ros::names::append(name, "fleet_scans"));
    v->c.vehicle = name;
    v->c.topic = v->topic;
    Vehicle* raw = v.get();
    // Checked deserialisation: no array is sized beyond the bytes a message carries (issue 42).
    v->sub = wavog_ros::subscribeChecked<wavog_mapping::PlacedScan>(
        nh_, v->topic, kSubscriberQueue,
        boost::function<void(const ros::MessageEvent<const wavog_mapping::PlacedScan>&)>(
            [this, raw](const ros::MessageEvent<const wavog_mapping::PlacedScan>& e) {
              try {
                onMessage(raw, e);
              } catch (const std::exception& ex) {
                ROS_ERROR_THROTTLE(kWarnPeriod, "%s: exception in the fleet callback: %s",
                                   raw->topic.c_str(), ex.what());
              }
            }),
        [this, raw](const wavog_mapping::PlacedScan& partial, const wavog_ros::Refused& r) {
          try {
            onRefused(raw, partial, r);
          } catch (const std::exception& ex) {
            ROS_ERROR_THROTTLE(kWarnPeriod, "%s: exception counting a refused message: %s",
                               raw->topic.c_str(), ex.what());
          }
        });
    updater->add(name + " vehicle", [this, raw](diagnostic_updater::DiagnosticStatusWrapper& s) {
      diagnose(raw, s);
    });
    vehicles_.push_back(std::move(v));
  }
  release_timer_ = nh_.createWallTimer(ros::WallDuration(kReleasePeriod),
                                       [this](const ros::WallTimerEvent&) { onReleaseTimer(); });
}

FleetReceiver::~FleetReceiver() {
  release_timer_.stop();
  for (auto& v : vehicles_) v->sub.shutdown();
}

void FleetReceiver::onRefused(Vehicle* v, const wavog_mapping::PlacedScan& partial,
                              const wavog_ros::Refused& r) {
  std::lock_guard<std::mutex> lock(*mutex_);
  v->last_receipt = ros::WallTime::now();
  takeInRefused(partial, r.bytes_read, r.length, r.why, &v->stream_index, &v->c);
  warnLocked(v, "message of " + std::to_string(r.length) +
                    " bytes refused before deserialisation (bad_length, " +
                    std::to_string(v->c.dropped_bad_length) + " so far): " + r.why);
}

void FleetReceiver::onMessage(Vehicle* v,
                              const ros::MessageEvent<const wavog_mapping::PlacedScan>& event) {
  const Item m = event.getConstMessage();
  const ros::WallTime now = ros::WallTime::now();
  std::lock_guard<std::mutex> lock(*mutex_);
  wavog_mapping::VehicleStatus& c = v->c;
  v->last_receipt = now;
  if (v->stale_reported) {
    v->stale_reported = false;
    ROS_INFO("%s: vehicle '%s' streams again", pnh_.getNamespace().c_str(), v->name.c_str());
  }
  const Intake in = takeIn(*m, limits_, ros::Time::now(), &v->stream_index, &c);
  if (in.step == IndexStep::kRegress) {
    warnLocked(v, "index " + std::to_string(m->index) + " at or below the previous one (" +
                      std::to_string(c.index_regressions) +
                      " so far: a duplicate or a restarted mapper; not counted as lost)");
  } else if (in.step == IndexStep::kJump) {
    warnLocked(v, "index " + std::to_string(m->index) + " more than 2^32 past the previous "
                      "one (" + std::to_string(c.index_jumps) +
                      " so far: a corrupt index; not counted as lost)");
  }
  if (in.refusal != Refusal::kNone) {
    warnLocked(v, std::string("message refused (") + toString(in.refusal) + ", " +
                      std::to_string(*refusalCounter(in.refusal, &c)) + " so far): " + in.detail);
    return;
  }
  c.last_stamp = m->header.stamp;
  const OrderKey key{toNs(m->header.stamp), v->index, m->index};
  // The stream's progress counts whether the scan is queued or late: either way nothing older
  // follows it on its input.
  if (!horizon_.note(static_cast<std::size_t>(v->index), m->input, key.stamp_ns, now.toSec())) {
    warnLocked(v, "input '" + m->input.substr(0, 64) + "' is one input more than the " +
                      std::to_string(horizon_.streams(static_cast<std::size_t>(v->index))) +
                      " tracked: the reorder buffer does not wait for it (its scans may come "
                      "late)");
  }
  switch (buffer_.push(key, now.toSec(), m)) {
    case Admission::kQueued:
      return;
    case Admission::kOverflow:
      ++c.dropped_overflow;
      warnLocked(v, "message refused: the reorder buffer holds fleet_max_buffered scans (" +
                        std::to_string(buffer_.size()) + ")");
      return;
    case Admission::kLate:
      if (integrate_late_) {
        ++c.integrated_late;
        integrateLocked(v, *m);
      } else {
        ++c.dropped_late;
      }
      warnLocked(v, "scan stamped " + std::to_string(m->header.stamp.toSec()) +
                        " s arrived after a newer one was integrated (" +
                        (integrate_late_ ? std::to_string(c.integrated_late) + " integrated late"
                                         : std::to_string(c.dropped_late) + " dropped") +
                        " so far; fleet_reorder_wait " + std::to_string(reorder_wait_) +
                        " s, fleet_reorder_max_wait " + std::to_string(reorder_max_wait_) +
                        " s, fleet_stale_timeout " + std::to_string(stale_timeout_) + " s)");
      return;
  }
}

void FleetReceiver::onReleaseTimer() {
  const double now = ros::WallTime::now().toSec();
  std::lock_guard<std::mutex> lock(*mutex_);
  buffer_.release(now, horizon_.horizon(now), [this](const OrderKey& key, const Item& m) {
    integrateLocked(vehicles_[static_cast<std::size_t>(key.vehicle)].get(), *m);
  });
}

std::size_t FleetReceiver::releaseAll() {
  std::lock_guard<std::mutex> lock(*mutex_);
  return buffer_.releaseAll([this](const OrderKey& key, const Item& m) {
    integrateLocked(vehicles_[static_cast<std::size_t>(key.vehicle)].get(), *m);
  });
}

void FleetReceiver::integrateLocked(Vehicle* v, const wavog_mapping::PlacedScan& m) {
  const wavog::IntegrateStats st = integrate_(placedPose(m), placedView(m, &decoded_));
  wavog_mapping::VehicleStatus& c = v->c;
  if (st.status != wavog::ScanStatus::kOk) {
    ++c.dropped_refused;
    warnLocked(v, std::string("scan refused by the core: ") + wavog::toString(st.status));
    return;
  }
  ++c.integrated;
  if (st.outside_region) c.outside_region = saturatingAdd(c.outside_region, 1);
  c.in_region = !st.outside_region;
  v->has_position = true;
  v->x = m.x;
  v->y = m.y;
  if (integrated_stamp_ < m.header.stamp) integrated_stamp_ = m.header.stamp;
  // In double seconds: ros::Time's operator- throws beyond 2^31 s (the stamp passed
  // fleet_max_stamp_offset, but the clock may have jumped since).
  const double lag = wavog_ros::secondsBetween(ros::Time::now(), m.header.stamp);
  c.lag = lag;
  v->lag_max_period = std::max(v->lag_max_period, lag);
  if (v->oldest_unpublished.isZero() || m.header.stamp < v->oldest_unpublished) {
    v->oldest_unpublished = m.header.stamp;
  }
}

void FleetReceiver::layersPublishedLocked(const ros::Time& now) {
  for (auto& v : vehicles_) {
    if (v->oldest_unpublished.isZero()) continue;
    v->publish_lag_max_period =
        std::max(v->publish_lag_max_period, wavog_ros::secondsBetween(now, v->oldest_unpublished));
    v->oldest_unpublished = ros::Time();
  }
}

bool FleetReceiver::latestPositionLocked(std::size_t i, double* x, double* y) const {
  if (i >= vehicles_.size() || !vehicles_[i]->has_position) return false;
  *x = vehicles_[i]->x;
  *y = vehicles_[i]->y;
  return true;
}

std::uint64_t FleetReceiver::integratedLocked() const {
  std::uint64_t n = 0;
  for (const auto& v : vehicles_) n += v->c.integrated;
  return n;
}

bool FleetReceiver::staleLocked(const Vehicle* v, const ros::WallTime& now) const {
  return v->last_receipt.isZero() || (now - v->last_receipt).toSec() > stale_timeout_;
}

void FleetReceiver::publishStatus(const ros::Time& now) {
  auto s = boost::make_shared<wavog_mapping::FleetStatus>();
  const ros::WallTime wall = ros::WallTime::now();
  {
    std::lock_guard<std::mutex> lock(*mutex_);
    s->header.stamp = now;
    s->header.frame_id = limits_.map_frame;
    for (auto& v : vehicles_) {
      v->c.stale = staleLocked(v.get(), wall);
      v->c.lag_max = v->lag_max_period;
      v->lag_max_period = 0.0;
      v->c.publish_lag_max = v->publish_lag_max_period;
      v->publish_lag_max_period = 0.0;
      s->vehicles.push_back(v->c);
    }
    s->buffered = buffer_.size();
    s->reorder_wait = reorder_wait_;
    s->integrated_stamp = integrated_stamp_;
  }
  status_pub_.publish(s);
}

void FleetReceiver::diagnose(const Vehicle* v, diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::lock_guard<std::mutex> lock(*mutex_);
  const ros::WallTime now = ros::WallTime::now();
  const wavog_mapping::VehicleStatus& c = v->c;
  const std::uint64_t refused = c.dropped_version + c.dropped_frame + c.dropped_bad_stamp +
                                c.dropped_bad_pose + c.dropped_bad_size + c.dropped_refused +
                                c.dropped_overflow + c.dropped_bad_length;
  if (staleLocked(v, now)) {
    if (v->last_receipt.isZero()) {
      stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "stale: nothing received yet");
    } else {
      stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN,
                    "stale: nothing received for %.1f s (its cells stay in the map)",
                    (now - v->last_receipt).toSec());
    }
  } else if (refused > 0) {
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN, "%llu messages refused",
                  static_cast<unsigned long long>(refused));
  } else {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "streaming");
  }
  stat.add("topic", c.topic);
  stat.add("received", c.received);
  stat.add("bytes", c.bytes);
  stat.add("integrated", c.integrated);
  stat.add("integrated late", c.integrated_late);
  stat.add("lost", c.lost);
  stat.add("outside region", c.outside_region);
  stat.add("index regressions", c.index_regressions);
  stat.add("index jumps", c.index_jumps);
  stat.add("dropped late", c.dropped_late);
  stat.add("dropped version", c.dropped_version);
  stat.add("dropped frame", c.dropped_frame);
  stat.add("dropped bad stamp", c.dropped_bad_stamp);
  stat.add("dropped bad pose", c.dropped_bad_pose);
  stat.add("dropped bad size", c.dropped_bad_size);
  stat.add("dropped bad length", c.dropped_bad_length);
  stat.add("dropped refused by core", c.dropped_refused);
  stat.add("dropped overflow", c.dropped_overflow);
  stat.add("last stamp", c.last_stamp.toSec());
  stat.add("lag (s)", c.lag);
}

void FleetReceiver::warnLocked(Vehicle* v, const std::string& text) {
  const ros::WallTime now = ros::WallTime::now();
  if (!v->last_warn.isZero() && (now - v->last_warn).toSec() < kWarnPeriod) return;
  v->last_warn = now;
  ROS_WARN("%s: %s", v->topic.c_str(), text.c_str());
}

}  // namespace wavog_fleet
