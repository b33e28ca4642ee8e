// MappingRos's timers: the full publication of every layer with the ~status of the period that
// ends (onPublishTimer -> publishAll, also called at the end of the input and by the services),
// and map_updates (onUpdateTimer). Both run on wall time, so that they go on after a bag's clock
// has stopped. The map is read under the lock; messages are built and sent after it is released,
// still under publish_mutex_, which keeps each update after the `map` it refers to.
#include <ros/ros.h>
#include <tf2/exceptions.h>

#include <boost/make_shared.hpp>
#include <chrono>

#include "fleet/fleet_receiver.h"
#include "fleet/vehicle_windows.h"
#include "mapping_ros_impl.h"

namespace wavog_ros {

void MappingRos::Impl::onPublishTimer(const ros::WallTimerEvent&) { publishAll(); }

bool MappingRos::Impl::windowCentre(const char* consequence, double* cx, double* cy) {
  const RosParams& rp = config_.ros;
  *cx = *cy = 0.0;
  std::string error;
  try {
    const auto t = buffer_->lookupTransform(rp.map_frame, rp.base_frame, ros::Time(0));
    *cx = t.transform.translation.x;
    *cy = t.transform.translation.y;
    return true;
  } catch (const tf2::TransformException& e) {
    error = e.what();
  }
  // No robot pose from tf: the sensor of the last scan stands in for it.
  bool have_sensor = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    have_sensor = publisher_->lastSensor(cx, cy);
  }
  if (have_sensor || rp.publish_window <= 0.0) return true;  // whole layers need no centre
  ROS_WARN_THROTTLE(kWarnPeriod, "%s: no pose of '%s' for publish_window and no scan yet, %s: %s",
                    pnh_.getNamespace().c_str(), rp.base_frame.c_str(), consequence, error.c_str());
  return false;
}

void MappingRos::Impl::publishAll() {
  // One publication at a time, and never between a map_updates read and its publication: an
  // update always refers to the last `map` sent.
  std::lock_guard<std::mutex> publishing(publish_mutex_);
  const auto t_start = std::chrono::steady_clock::now();
  const ros::Time now = ros::Time::now();
  const RosParams& rp = config_.ros;

  // Without a window centre nothing is published but ~status.
  double cx = 0.0, cy = 0.0;
  const bool window_ok = windowCentre("maps not published", &cx, &cy);

  Layers layers;
  std::vector<wavog_fleet::VehicleWindows::Window> windows;
  wavog_mapping::MapperStatus::Ptr status;
  wavog::GridValues values;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    values = rp.grid_values;
    if (fleet_windows_) {
      windows = fleet_windows_->readLocked(map_, [this](std::size_t i, double* x, double* y) {
        return fleet_->latestPositionLocked(i, x, y);
      });
    }
    if (window_ok) {
      layers = publisher_->read(map_, rp, cx, cy);
      changed_since_publish_ = false;
      if (fleet_ && layers.refused.empty()) fleet_->layersPublishedLocked(now);
    }
    layers_refused_ += layers.refused.size();
    status = statusLocked(now);
  }
  if (!layers.refused.empty()) {
    std::string text;
    for (const auto& r : layers.refused) text += " " + r + ";";
    ROS_ERROR_THROTTLE(kWarnPeriod,
                       "%s: layers not published, more than %.0f cells (the limit of one layer):%s "
                       "make publish_window smaller",
                       pnh_.getNamespace().c_str(), kMaxLayerCells, text.c_str());
  }
  // Said once each time it starts: a layer too large as a whole goes out as a window.
  if (!layers.windowed.empty() && !windowed_warned_) {
    std::string text;
    for (const auto& w : layers.windowed) text += " " + w + ";";
    ROS_WARN(
        "%s: the map has grown beyond %.0f cells (the limit of one layer):%s each such layer "
        "is published as the square around '%s' (else the last scan's sensor) from now on; "
        "the coarser layers stay whole while they fit (set publish_window to choose the "
        "square)",
        pnh_.getNamespace().c_str(), kMaxLayerCells, text.c_str(), rp.base_frame.c_str());
  }
  if (window_ok) windowed_warned_ = !layers.windowed.empty();
  MapPublisher::publish(layers, rp.map_frame, now);
  wavog_fleet::VehicleWindows::publish(windows, values, rp.map_frame, now);
  status_pub_.publish(status);
  if (fleet_) fleet_->publishStatus(now);
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  std::lock_guard<std::mutex> lock(mutex_);
  publish_time_ = elapsed;
}

void MappingRos::Impl::publishStatus() {
  wavog_mapping::MapperStatus::Ptr status;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    status = statusLocked(ros::Time::now());
  }
  status_pub_.publish(status);
}

wavog_mapping::MapperStatus::Ptr MappingRos::Impl::statusLocked(const ros::Time& now) {
  auto status = boost::make_shared<wavog_mapping::MapperStatus>();
  const double period = secondsBetween(now, last_status_time_);  // a /clock may be anything
  last_status_time_ = now;
  status->header.stamp = now;
  status->header.frame_id = config_.ros.map_frame;
  for (const auto& in : inputs_) {
    InputCounters& c = in->c;
    c.rate = period > 0.0 ? static_cast<double>(c.received_in_period) / period : 0.0;
    c.received_in_period = 0;
    status->inputs.push_back(toInputStatus(c, in->topic, in->config.expected_rate));
    status->scans_integrated += c[Counter::kIntegrated];
    status->tf_failures += c.tfFailures();
  }
  if (fleet_) status->scans_integrated += fleet_->integratedLocked();
  status->clock_jumps = clock_jumps_;
  status->exceptions = exceptions_;
  status->layers_refused = layers_refused_;
  status->tf_refused = tf_refused_;
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
  status->tiles = ms.tiles;
  status->bytes = ms.bytes;
  return status;
}

void MappingRos::Impl::onUpdateTimer(const ros::WallTimerEvent&) {
  std::lock_guard<std::mutex> publishing(publish_mutex_);  // see publishAll()
  const ros::Time now = ros::Time::now();
  wavog::GridValues values;
  if (fleet_windows_) {
    std::vector<wavog_fleet::VehicleWindows::Window> updates;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      values = config_.ros.grid_values;
      updates = fleet_windows_->readUpdatesLocked(map_);
    }
    wavog_fleet::VehicleWindows::publishUpdates(updates, values, config_.ros.map_frame, now);
  }
  if (!publisher_->updateWanted()) return;
  wavog::Raster raster;
  wavog::CellBox full;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    values = config_.ros.grid_values;
    if (!publisher_->readUpdate(map_, &raster, &full)) return;
  }
  publisher_->publishUpdate(raster, full, values, config_.ros.map_frame, now);
}

}  // namespace wavog_ros
