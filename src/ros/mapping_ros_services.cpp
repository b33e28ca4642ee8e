// MappingRos's services: ~reset (forget the map), ~clear_region (forget a box) and ~save_map (the
// native map plus one map_server image per published scale). Each answers with success and a
// message; none throws.
#include <ros/ros.h>

#include <cmath>

#include "mapping_ros_impl.h"
#include "save_path.h"
#include "wavog_mapping/io/image_io.h"

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
}

bool MappingRos::Impl::onReset(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  std::lock_guard<std::mutex> lock(mutex_);
  map_.reset();
  publisher_->markAllDirty(map_.resolution());
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
  publisher_->touched({req.min_x, req.min_y, req.max_x, req.max_y});
  res.success = true;
  res.message = "cleared";
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
  // <stem>: the path without its extension; images go beside the map file.
  const std::size_t slash = req.path.find_last_of('/');
  const std::size_t dot = req.path.find_last_of('.');
  const std::string stem = (dot != std::string::npos && (slash == std::string::npos || dot > slash))
                               ? req.path.substr(0, dot)
                               : req.path;
  std::vector<wavog::Raster> rasters;
  std::string refused;  // layers too large for an image
  {
    std::lock_guard<std::mutex> lock(mutex_);
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
    return fail(e.what());
  }
  res.success = true;
  res.message = "saved " + std::to_string(res.files.size()) + " files";
  if (!refused.empty()) {
    res.message += "; no image of" + refused + ": more than " +
                   std::to_string(static_cast<long long>(kMaxLayerCells)) + " cells";
    ROS_ERROR("%s: save_map: %s", pnh_.getNamespace().c_str(), res.message.c_str());
  }
  ROS_INFO("%s: map saved to %s (+ %zu map_server images)", pnh_.getNamespace().c_str(),
           req.path.c_str(), rasters.size());
  return true;
}

}  // namespace wavog_ros
