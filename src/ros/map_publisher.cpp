// Publication of the layers and of map_updates (see map_publisher.h).
#include "map_publisher.h"

#include <map_msgs/OccupancyGridUpdate.h>
#include <nav_msgs/MapMetaData.h>
#include <nav_msgs/OccupancyGrid.h>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "wavog_mapping/io/map_files.h"

namespace wavog_ros {
namespace {

wavog::Raster emptyRaster(int scale, double resolution) {
  wavog::Raster r;
  r.scale = scale;
  r.cell_size = resolution * static_cast<double>(1 << scale);
  return r;
}

// A raster over `box` with every cell unknown.
wavog::Raster unknownRaster(int scale, double resolution, const wavog::CellBox& box) {
  wavog::Raster r = emptyRaster(scale, resolution);
  r.box = box;
  const auto n = static_cast<std::size_t>(box.width()) * static_cast<std::size_t>(box.height());
  r.log_odds.assign(n, 0.0f);
  r.known.assign(n, 0);
  return r;
}

std::string cellsText(const wavog::CellBox& box) {
  return std::to_string(box.width()) + " x " + std::to_string(box.height()) + " cells";
}

/// [lo, hi] clipped to [clip_lo, clip_hi]; false when empty or not finite.
bool clip(double clip_lo, double clip_hi, double* lo, double* hi) {
  *lo = std::max(*lo, clip_lo);
  *hi = std::min(*hi, clip_hi);
  return std::isfinite(*lo) && std::isfinite(*hi) && *lo <= *hi;
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

MapPublisher::MapPublisher(const ros::NodeHandle& nh, const std::vector<int>& scales,
                           bool reflection, bool ndt)
    : nh_(nh), reflection_(reflection), ndt_(ndt) {
  map_pub_ = nh_.advertise<nav_msgs::OccupancyGrid>("map", 1, true);
  metadata_pub_ = nh_.advertise<nav_msgs::MapMetaData>("map_metadata", 1, true);
  update_pub_ = nh_.advertise<map_msgs::OccupancyGridUpdate>("map_updates", 10);
  if (reflection_) reflection_pub_ = nh_.advertise<nav_msgs::OccupancyGrid>("reflection", 1, true);
  if (ndt_) {
    ndt_markers_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("ndt_markers", 1, true);
    ndt_cells_pub_ = nh_.advertise<sensor_msgs::PointCloud2>("ndt_cells", 1, true);
  }
  advertiseScales(scales);
}

namespace {
// Publishers of `prefix`<s> (messages M) for exactly `scales`, keeping those of `old` that stay.
template <typename M>
std::map<int, ros::Publisher> scalePublishers(ros::NodeHandle& nh, const std::string& prefix,
                                              const std::vector<int>& scales,
                                              const std::map<int, ros::Publisher>& old) {
  std::map<int, ros::Publisher> pubs;
  for (int s : scales) {
    auto it = old.find(s);
    pubs[s] = it != old.end() ? it->second : nh.advertise<M>(prefix + std::to_string(s), 1);
  }
  return pubs;
}

// The publisher of scale s in `pubs` if it has subscribers, else a null one.
ros::Publisher ifSubscribed(const std::map<int, ros::Publisher>& pubs, int s) {
  const auto it = pubs.find(s);
  return it != pubs.end() && it->second.getNumSubscribers() > 0 ? it->second : ros::Publisher();
}
}  // namespace

void MapPublisher::advertiseScales(const std::vector<int>& scales) {
  scale_pubs_ = scalePublishers<nav_msgs::OccupancyGrid>(nh_, "map_scale_", scales, scale_pubs_);
  if (reflection_) {
    reflection_scale_pubs_ = scalePublishers<nav_msgs::OccupancyGrid>(
        nh_, "reflection_scale_", scales, reflection_scale_pubs_);
  }
  if (ndt_) {
    ndt_markers_scale_pubs_ = scalePublishers<visualization_msgs::MarkerArray>(
        nh_, "ndt_markers_scale_", scales, ndt_markers_scale_pubs_);
    ndt_cells_scale_pubs_ = scalePublishers<sensor_msgs::PointCloud2>(
        nh_, "ndt_cells_scale_", scales, ndt_cells_scale_pubs_);
  }
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

void MapPublisher::sensorAt(double x, double y) {
  if (!std::isfinite(x) || !std::isfinite(y)) return;
  have_sensor_ = true;
  sensor_x_ = x;
  sensor_y_ = y;
}

bool MapPublisher::lastSensor(double* x, double* y) const {
  *x = sensor_x_;
  *y = sensor_y_;
  return have_sensor_;
}

LayerSize readOccupancy(const wavog::WaveletMap& map, int scale, const RosParams& params, double cx,
                        double cy, wavog::Raster* raster, std::string* refused,
                        std::string* windowed) {
  // With a window, the read-out costs what the window holds, never the whole map.
  wavog::CellBox box;
  LayerSize size = layerBox(map, scale, params.publish_window, cx, cy, &box);
  *raster = emptyRaster(scale, map.resolution());
  if (size == LayerSize::kTooLarge && params.publish_window <= 0.0) {
    // The whole layer is too large for one message: the square around the robot instead.
    const wavog::CellBox whole = box;
    size = layerBox(map, scale, kFallbackWindowCells * std::ldexp(map.resolution(), scale), cx, cy,
                    &box);
    if (size == LayerSize::kOk) {
      *windowed = "scale " + std::to_string(scale) + ": " + cellsText(whole) + ", published as " +
                  cellsText(box);
    }
  }
  if (size == LayerSize::kTooLarge)
    *refused = "scale " + std::to_string(scale) + ": " + cellsText(box);
  if (size != LayerSize::kOk) return size;
  const wavog::Aggregation aggregation =
      scale == 0 ? wavog::Aggregation::kMean : params.scale_aggregation;
  // Cut to the observed cells: stored blocks are whole (2^block_levels cells a side) and a
  // window may reach beyond what was seen; neither belongs in the message.
  wavog::Raster r = map.exportScale(scale, box, aggregation);
  wavog::CellBox known;
  if (wavog::knownBox(r, &known)) *raster = wavog::cropToKnown(r, 0);
  return size;
}

Layers MapPublisher::read(const wavog::WaveletMap& map, const RosParams& params, double cx,
                          double cy) {
  Layers out;
  out.values = params.grid_values;
  // `map`, `reflection`, `ndt_markers` and `ndt_cells` are latched: always published. A scale
  // layer nobody listens to costs nothing; a payload's scale layer reads its occupancy layer for
  // the box, publishing that only when it has listeners too.
  Layers::Layer finest;
  finest.pub = map_pub_;
  finest.metadata_pub = metadata_pub_;
  finest.reflection_pub = reflection_pub_;
  finest.ndt_markers_pub = ndt_markers_pub_;
  finest.ndt_cells_pub = ndt_cells_pub_;
  out.layers.push_back(std::move(finest));
  for (const auto& sp : scale_pubs_) {
    Layers::Layer layer;
    layer.scale = sp.first;
    layer.pub = ifSubscribed(scale_pubs_, sp.first);
    layer.reflection_pub = ifSubscribed(reflection_scale_pubs_, sp.first);
    layer.ndt_markers_pub = ifSubscribed(ndt_markers_scale_pubs_, sp.first);
    layer.ndt_cells_pub = ifSubscribed(ndt_cells_scale_pubs_, sp.first);
    if (layer.pub || layer.reflection_pub || layer.ndt_markers_pub || layer.ndt_cells_pub) {
      out.layers.push_back(std::move(layer));
    }
  }
  for (Layers::Layer& layer : out.layers) {
    std::string refused, windowed;
    if (readOccupancy(map, layer.scale, params, cx, cy, &layer.raster, &refused, &windowed) ==
        LayerSize::kTooLarge) {
      out.refused.push_back(refused);
    }
    if (!windowed.empty()) out.windowed.push_back(windowed);
    if (layer.raster.box.empty()) {
      // Nothing observed (yet, or since ~reset): a layer sent before is sent again over its last
      // box, every cell unknown, so that latched and late subscribers see the reset; before its
      // first publication it is not sent at all (as gmapping before its first map).
      const auto last = last_box_.find(layer.scale);
      if (last != last_box_.end() && refused.empty()) {
        layer.raster = unknownRaster(layer.scale, map.resolution(), last->second);
      } else {
        layer.pub = ros::Publisher();
        layer.metadata_pub = ros::Publisher();
      }
    }
    if (layer.pub) last_box_[layer.scale] = layer.raster.box;
    if (layer.reflection_pub) {
      layer.reflection = map.exportReflection(layer.scale, layer.raster.box);
      layer.reflection.cell_size = layer.raster.cell_size;  // also for an empty box
    }
    if (layer.ndt_markers_pub || layer.ndt_cells_pub) {
      if (!layer.raster.box.empty()) layer.ndt = map.exportNdt(layer.scale, layer.raster.box);
      layer.ndt.scale = layer.scale;
      layer.ndt.cell_size = layer.raster.cell_size;  // also for an empty box
    }
    if (layer.scale == 0 && layer.pub) {
      // The dirty region is reset by map_updates only: re-sending an area the full map already
      // carries is harmless, while two timers of the same period would otherwise starve updates.
      // Updates wait until a box has gone out twice: topics are separate connections, and an
      // update must not overtake the first `map` of a new box on its way to a subscriber.
      const wavog::CellBox& b = layer.raster.box;
      full_box_stable_ = have_full_ && b.min_x == last_full_box_.min_x &&
                         b.min_y == last_full_box_.min_y && b.max_x == last_full_box_.max_x &&
                         b.max_y == last_full_box_.max_y;
      have_full_ = true;
      last_full_box_ = b;
    }
  }
  return out;
}

void MapPublisher::publish(const Layers& layers, const std::string& frame, const ros::Time& stamp) {
  for (const Layers::Layer& layer : layers.layers) {
    if (layer.pub) {
      const nav_msgs::OccupancyGrid::Ptr grid =
          toOccupancyGridMsg(layer.raster, layers.values, frame, stamp);
      layer.pub.publish(grid);
      if (layer.metadata_pub) layer.metadata_pub.publish(grid->info);
    }
    if (layer.reflection_pub) {
      layer.reflection_pub.publish(toOccupancyGridMsg(layer.reflection, frame, stamp));
    }
    if (layer.ndt_markers_pub) layer.ndt_markers_pub.publish(toNdtMarkers(layer.ndt, frame, stamp));
    if (layer.ndt_cells_pub) layer.ndt_cells_pub.publish(toNdtCloud(layer.ndt, frame, stamp));
  }
}

bool MapPublisher::readUpdate(const wavog::WaveletMap& map, wavog::Raster* raster,
                              wavog::CellBox* full) {
  if (!dirty_.any || !have_full_ || !full_box_stable_) return false;
  *full = last_full_box_;
  // The dirty region clipped to the last full map in metres first: a scan's reach may be huge.
  MapBox d = dirty_.box;
  const double res = map.resolution();
  dirty_.any = false;
  if (!clip(static_cast<double>(full->min_x) * res, static_cast<double>(full->max_x) * res,
            &d.min_x, &d.max_x) ||
      !clip(static_cast<double>(full->min_y) * res, static_cast<double>(full->max_y) * res,
            &d.min_y, &d.max_y)) {
    return false;
  }
  wavog::CellBox box = map.boxAround(d.min_x, d.min_y, d.max_x, d.max_y, 0);
  box.min_x = std::max(box.min_x, full->min_x);
  box.min_y = std::max(box.min_y, full->min_y);
  box.max_x = std::min(box.max_x, full->max_x);
  box.max_y = std::min(box.max_y, full->max_y);
  if (box.empty()) return false;
  *raster = map.exportScale(0, box, wavog::Aggregation::kMean);
  return true;
}

void MapPublisher::publishUpdate(const wavog::Raster& raster, const wavog::CellBox& full,
                                 const wavog::GridValues& values, const std::string& frame,
                                 const ros::Time& stamp) const {
  update_pub_.publish(
      toOccupancyGridUpdateMsg(raster, full.min_x, full.min_y, values, frame, stamp));
}

}  // namespace wavog_ros
