// MappingRos's services: ~reset (forget the map), ~clear_region (forget a box), ~save_map (the
// native map plus one map_server image per published scale, named and cropped as wavog_offline
// does) and ~flush (the end of the input now: waiting scans, one more publication). Each answers
// with success and a message; none throws.
#include <ros/ros.h>

#include <cmath>
#include <filesystem>
#include <system_error>

#include "mapping_ros_impl.h"
#include "wavog_mapping/io/image_io.h"
#include "wavog_mapping/io/map_files.h"

namespace wavog_ros {

bool MappingRos::Impl::onReset(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  std::lock_guard<std::mutex> lock(mutex_);
  map_.reset();
  publisher_->markAllDirty(map_.resolution());
  changed_since_publish_ = true;
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
  changed_since_publish_ = true;
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
  // The folder is created when missing; images go beside the map file as wavog_offline names
  // them: <stem>_s<scale>.pgm/.yaml, <stem> being the path without its extension.
  const std::filesystem::path dir = std::filesystem::path(req.path).parent_path();
  if (!dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) {
      res.success = false;
      res.message = "cannot create the folder '" + dir.string() + "': " + ec.message();
      return true;
    }
  }
  const std::string stem = wavog::pathStem(req.path);
  // Scans still waiting for tf belong to the saved map (at the end of a bag they would wait
  // forever).
  flushPending();
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
    for (int s : publisher_->scales()) scales.push_back(s);
    for (int s : scales) {
      wavog::CellBox box;
      if (map_.bounds(s, &box) && !box.empty()) {
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

}  // namespace wavog_ros
