// MappingRos's services: ~reset (forget the map), ~clear_region (forget a box), ~save_map (the
// native map plus one map_server image per published scale, named and cropped as wavog_offline
// does), ~flush (the end of the input now: waiting scans, one more publication) and dynamic_map
// (nav_msgs/GetMap: the `map` layer as a publication now would carry it). Each answers with
// success and a message, or for dynamic_map false, logged; none throws.
#include <ros/ros.h>

#include <cmath>
#include <filesystem>
#include <system_error>
#include <utility>

#include "mapping_ros_impl.h"
#include "save_path.h"
#include "wavog_mapping/io/image_io.h"
#include "wavog_mapping/io/map_files.h"

namespace wavog_ros {

void MappingRos::Impl::advertiseServices() {
  using wavog_mapping::ClearRegion;
  using wavog_mapping::SaveMap;
  reset_srv_ = pnh_.advertiseService<std_srvs::Empty::Request, std_srvs::Empty::Response>(
      "reset", [this](std_srvs::Empty::Request& req, std_srvs::Empty::Response& res) {
        bool ok = false;
        guarded("reset service", nullptr, [&] { ok = onReset(req, res); });
        return ok;
      });
  clear_srv_ = pnh_.advertiseService<ClearRegion::Request, ClearRegion::Response>(
      "clear_region", [this](ClearRegion::Request& req, ClearRegion::Response& res) {
        res.success = false;
        res.message = "internal error (logged)";
        guarded("clear_region service", nullptr, [&] { onClearRegion(req, res); });
        return true;
      });
  save_srv_ = pnh_.advertiseService<SaveMap::Request, SaveMap::Response>(
      "save_map", [this](SaveMap::Request& req, SaveMap::Response& res) {
        res.success = false;
        res.message = "internal error (logged)";
        guarded("save_map service", nullptr, [&] { onSaveMap(req, res); });
        return true;
      });
  flush_srv_ = pnh_.advertiseService<std_srvs::Trigger::Request, std_srvs::Trigger::Response>(
      "flush", [this](std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res) {
        res.success = false;
        res.message = "internal error (logged)";
        guarded("flush service", nullptr, [&] { onFlush(req, res); });
        return true;
      });
  // Beside `map` (nh_), not private: the layer's own service, under the name gmapping,
  // hector_mapping and slam_karto serve it, found without knowing the node's name. The node's
  // commands above are private (~).
  dynamic_map_srv_ = nh_.advertiseService<nav_msgs::GetMap::Request, nav_msgs::GetMap::Response>(
      "dynamic_map", [this](nav_msgs::GetMap::Request&, nav_msgs::GetMap::Response& res) {
        bool ok = false;
        guarded("dynamic_map service", nullptr, [&] { ok = onDynamicMap(res); });
        return ok;
      });
}

bool MappingRos::Impl::onReset(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    map_.reset();
    publisher_->markAllDirty(map_.resolution());
    changed_since_publish_ = true;
  }
  ROS_INFO("%s: map reset", pnh_.getNamespace().c_str());
  publishAll();  // now, not at the next timer: after a bag the clock may have stopped
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
  {
    std::lock_guard<std::mutex> lock(mutex_);
    map_.clearBox(req.min_x, req.min_y, req.max_x, req.max_y);
    publisher_->touched({req.min_x, req.min_y, req.max_x, req.max_y});
    changed_since_publish_ = true;
  }
  publishAll();  // as onReset
  res.success = true;
  res.message = "cleared; published";
  return true;
}

bool MappingRos::Impl::onSaveMap(wavog_mapping::SaveMap::Request& req,
                                 wavog_mapping::SaveMap::Response& res) {
  // Every refusal and failure is logged as well as answered.
  const auto fail = [this, &res](const std::string& message) {
    res.success = false;
    res.message = message;
    ROS_ERROR("%s: save_map failed: %s", pnh_.getNamespace().c_str(), message.c_str());
    return true;
  };
  std::string resolved, refusal;
  if (!resolveSavePath(config_.ros.map_dir, req.path, &resolved, &refusal)) return fail(refusal);
  req.path = resolved;  // below map_dir; relative names resolved under it
  // The folder is created when missing; images go beside the map file as wavog_offline names
  // them: <stem>_s<scale>.pgm/.yaml, <stem> being the path without its extension.
  const std::filesystem::path dir = std::filesystem::path(req.path).parent_path();
  if (!dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) return fail("cannot create the folder '" + dir.string() + "': " + ec.message());
  }
  const std::string stem = wavog::pathStem(req.path);
  // Scans still waiting for tf belong to the saved map (at the end of a bag they would wait
  // forever).
  flushPending();
  std::vector<wavog::Raster> rasters;
  std::string refused;         // layers too large for an image
  wavog::RenderOptions image;  // map_server images with the published values and thresholds
  {
    std::lock_guard<std::mutex> lock(mutex_);
    image.values = config_.ros.grid_values;
    try {
      map_.save(req.path);
    } catch (const wavog::MapIoError& e) {
      return fail(e.what());
    }
    std::vector<int> scales = {0};
    for (int s : publisher_->scales()) scales.push_back(s);
    for (int s : scales) {
      wavog::CellBox box;
      const LayerSize size = layerBox(map_, s, 0.0, 0.0, 0.0, &box);
      if (size == LayerSize::kTooLarge) {
        ++layers_refused_;
        refused += " scale " + std::to_string(s) + " (" + std::to_string(box.width()) + " x " +
                   std::to_string(box.height()) + " cells)";
      }
      if (size == LayerSize::kOk) {
        rasters.push_back(wavog::cropToKnown(map_.exportScale(
            s, box, s == 0 ? wavog::Aggregation::kMean : config_.ros.scale_aggregation)));
      }
    }
  }
  res.files.push_back(req.path);
  try {
    for (const wavog::Raster& r : rasters) {
      const std::string base = wavog::scaleFileBase(stem, r.scale);
      res.files.push_back(base + ".pgm");
      res.files.push_back(wavog::writeMapServerMap(base, r, image));
    }
  } catch (const std::exception& e) {
    return fail(e.what());
  }
  res.success = true;
  res.message = savedMessage(res.files);  // names the folder: a relative path went below map_dir
  if (!refused.empty()) {
    res.message += "; no image of" + refused + ": more than " +
                   std::to_string(static_cast<long long>(kMaxLayerCells)) + " cells";
    ROS_ERROR("%s: save_map: %s", pnh_.getNamespace().c_str(), res.message.c_str());
  }
  ROS_INFO("%s: map saved to %s (+ %zu map_server images)", pnh_.getNamespace().c_str(),
           req.path.c_str(), rasters.size());
  publishAll();  // the saved map is also the published one
  return true;
}

bool MappingRos::Impl::onFlush(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  const std::size_t n = flushPending();
  publishAll();
  res.success = true;
  res.message = std::to_string(n) + " waiting scan(s) integrated with the latest tf; published";
  return true;
}

bool MappingRos::Impl::onDynamicMap(nav_msgs::GetMap::Response& res) {
  const RosParams& rp = config_.ros;
  double cx = 0.0, cy = 0.0;
  if (!windowCentre("dynamic_map not answered", &cx, &cy)) return false;
  const ros::Time now = ros::Time::now();
  wavog::Raster raster;
  std::string refused, windowed;
  LayerSize size = LayerSize::kEmpty;
  wavog::GridValues values;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    size = readOccupancy(map_, 0, rp, cx, cy, &raster, &refused, &windowed);
    if (size == LayerSize::kTooLarge) ++layers_refused_;
    values = rp.grid_values;
  }
  if (size == LayerSize::kTooLarge) {
    ROS_ERROR_THROTTLE(kWarnPeriod,
                       "%s: dynamic_map refused: the map layer (%s) has more than %.0f cells (the "
                       "limit of one layer); make publish_window smaller",
                       pnh_.getNamespace().c_str(), refused.c_str(), kMaxLayerCells);
    return false;
  }
  if (raster.box.empty()) {  // as gmapping before its first map: nothing to serve yet
    ROS_WARN_THROTTLE(kWarnPeriod, "%s: dynamic_map not answered: no observed cell%s yet",
                      pnh_.getNamespace().c_str(),
                      rp.publish_window > 0.0 ? " in publish_window" : "");
    return false;
  }
  res.map = std::move(*toOccupancyGridMsg(raster, values, rp.map_frame, now));
  return true;
}

}  // namespace wavog_ros
