// Publication of the layers and of map_updates (see map_publisher.h).
#include "map_publisher.h"

#include <map_msgs/OccupancyGridUpdate.h>
#include <nav_msgs/OccupancyGrid.h>

#include <algorithm>

#include "wavog_mapping/io/map_files.h"
#include "wavog_mapping/ros/conversions.h"

namespace wavog_ros {
namespace {

wavog::Raster emptyRaster(int scale, double resolution) {
  wavog::Raster r;
  r.scale = scale;
  r.cell_size = resolution * static_cast<double>(1 << scale);
  return r;
}

}  // namespace

void DirtyRegion::add(const MapBox& b) {
  if (!any) {
    box = b;
    any = true;
    return;
  }
  box.min_x = std::min(box.min_x, b.min_x);
  box.min_y = std::min(box.min_y, b.min_y);
  box.max_x = std::max(box.max_x, b.max_x);
  box.max_y = std::max(box.max_y, b.max_y);
}

MapPublisher::MapPublisher(const ros::NodeHandle& nh, const std::vector<int>& scales) : nh_(nh) {
  map_pub_ = nh_.advertise<nav_msgs::OccupancyGrid>("map", 1, true);
  update_pub_ = nh_.advertise<map_msgs::OccupancyGridUpdate>("map_updates", 10);
  advertiseScales(scales);
}

void MapPublisher::advertiseScales(const std::vector<int>& scales) {
  std::map<int, ros::Publisher> pubs;
  for (int s : scales) {
    auto it = scale_pubs_.find(s);
    pubs[s] = it != scale_pubs_.end()
                  ? it->second
                  : nh_.advertise<nav_msgs::OccupancyGrid>("map_scale_" + std::to_string(s), 1);
  }
  scale_pubs_.swap(pubs);
}

std::vector<int> MapPublisher::scales() const {
  std::vector<int> s;
  for (const auto& sp : scale_pubs_) s.push_back(sp.first);
  return s;
}

void MapPublisher::markAllDirty(double resolution) {
  if (!have_full_) return;
  const auto m = [resolution](std::int64_t cell) { return static_cast<double>(cell) * resolution; };
  dirty_.add({m(last_full_box_.min_x), m(last_full_box_.min_y), m(last_full_box_.max_x),
              m(last_full_box_.max_y)});
}

Layers MapPublisher::read(const wavog::WaveletMap& map, const RosParams& params, double cx,
                          double cy) {
  Layers out;
  // `map` is latched: always published. A scale layer nobody listens to costs nothing.
  out.layers.push_back({0, map_pub_, {}});
  for (const auto& sp : scale_pubs_) {
    if (sp.second.getNumSubscribers() > 0) out.layers.push_back({sp.first, sp.second, {}});
  }
  for (Layers::Layer& layer : out.layers) {
    // With a window, the read-out costs what the window holds, never the whole map.
    wavog::CellBox box;
    bool have = true;
    if (params.publish_window > 0.0) {
      const double w = params.publish_window;
      box = map.boxAround(cx - w, cy - w, cx + w, cy + w, layer.scale);
    } else {
      have = map.bounds(layer.scale, &box);
    }
    const wavog::Aggregation aggregation =
        layer.scale == 0 ? wavog::Aggregation::kMean : params.scale_aggregation;
    // Cut to the observed cells: stored blocks are whole (2^block_levels cells a side) and a
    // window may reach beyond what was seen; neither belongs in the message.
    wavog::CellBox known;
    layer.raster = emptyRaster(layer.scale, map.resolution());
    if (have && !box.empty()) {
      wavog::Raster r = map.exportScale(layer.scale, box, aggregation);
      if (wavog::knownBox(r, &known)) layer.raster = wavog::cropToKnown(r, 0);
    }
    if (layer.scale == 0) {
      // The dirty region is reset by map_updates only: re-sending an area the full map already
      // carries is harmless, while two timers of the same period would otherwise starve updates.
      have_full_ = true;
      last_full_box_ = layer.raster.box;
    }
  }
  return out;
}

void MapPublisher::publish(const Layers& layers, const std::string& frame,
                           const ros::Time& stamp) {
  for (const Layers::Layer& layer : layers.layers) {
    layer.pub.publish(toOccupancyGridMsg(layer.raster, frame, stamp));
  }
}

bool MapPublisher::readUpdate(const wavog::WaveletMap& map, wavog::Raster* raster,
                              wavog::CellBox* full) {
  if (!dirty_.any || !have_full_) return false;
  *full = last_full_box_;
  const MapBox& d = dirty_.box;
  wavog::CellBox box = map.boxAround(d.min_x, d.min_y, d.max_x, d.max_y, 0);
  box.min_x = std::max(box.min_x, full->min_x);
  box.min_y = std::max(box.min_y, full->min_y);
  box.max_x = std::min(box.max_x, full->max_x);
  box.max_y = std::min(box.max_y, full->max_y);
  dirty_.any = false;
  if (box.empty()) return false;
  *raster = map.exportScale(0, box, wavog::Aggregation::kMean);
  return true;
}

void MapPublisher::publishUpdate(const wavog::Raster& raster, const wavog::CellBox& full,
                                 const std::string& frame, const ros::Time& stamp) const {
  update_pub_.publish(toOccupancyGridUpdateMsg(raster, full.min_x, full.min_y, frame, stamp));
}

}  // namespace wavog_ros
