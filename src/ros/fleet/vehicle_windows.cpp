// VehicleWindows (see vehicle_windows.h).
#include "vehicle_windows.h"

#include <map_msgs/OccupancyGridUpdate.h>
#include <nav_msgs/OccupancyGrid.h>

#include <algorithm>
#include <cmath>

#include "wavog_mapping/ros/conversions.h"

namespace wavog_fleet {

wavog::CellBox windowCells(const wavog::WaveletMap& map, double x, double y, double half_width) {
  const wavog::CellBox centre = map.boxAround(x, y, x, y, 0);  // the cell holding (x, y)
  if (centre.empty() || !(half_width >= 0.0)) return wavog::CellBox{};
  const std::int64_t k = std::llround(half_width / map.resolution());
  return wavog::CellBox{centre.min_x - k, centre.min_y - k, centre.min_x + k + 1,
                        centre.min_y + k + 1};
}

VehicleWindows::VehicleWindows(ros::NodeHandle nh, const std::vector<std::string>& vehicles,
                               double half_width)
    : half_width_(half_width) {
  for (const std::string& name : vehicles) {
    Vehicle v;
    v.map_pub =
        nh.advertise<nav_msgs::OccupancyGrid>(ros::names::append(name, "fleet_map"), 1, true);
    v.update_pub = nh.advertise<map_msgs::OccupancyGridUpdate>(
        ros::names::append(name, "fleet_map_updates"), 10);
    vehicles_.push_back(v);
  }
}

std::vector<VehicleWindows::Window> VehicleWindows::readLocked(const wavog::WaveletMap& map,
                                                               const PositionFn& position) {
  std::vector<Window> out;
  for (std::size_t i = 0; i < vehicles_.size(); ++i) {
    Vehicle& v = vehicles_[i];
    double x = 0.0, y = 0.0;
    if (v.map_pub.getNumSubscribers() == 0 && v.update_pub.getNumSubscribers() == 0) continue;
    if (!position(i, &x, &y)) continue;
    const wavog::CellBox box = windowCells(map, x, y, half_width_);
    if (box.empty() || !wavog::readoutFits(box)) continue;  // fleet_window is checked at start
    Window w;
    w.pub = v.map_pub;
    w.raster = map.exportScale(0, box, wavog::Aggregation::kMean);
    w.full = box;
    v.have_full = true;
    v.full = box;
    out.push_back(std::move(w));
  }
  return out;
}

std::vector<VehicleWindows::Window> VehicleWindows::readUpdatesLocked(
    const wavog::WaveletMap& map) {
  std::vector<Window> out;
  if (!dirty_.any) return out;
  const wavog::CellBox d =
      map.boxAround(dirty_.box.min_x, dirty_.box.min_y, dirty_.box.max_x, dirty_.box.max_y, 0);
  dirty_.any = false;
  for (Vehicle& v : vehicles_) {
    if (!v.have_full || v.update_pub.getNumSubscribers() == 0) continue;
    wavog::CellBox box;
    box.min_x = std::max(d.min_x, v.full.min_x);
    box.min_y = std::max(d.min_y, v.full.min_y);
    box.max_x = std::min(d.max_x, v.full.max_x);
    box.max_y = std::min(d.max_y, v.full.max_y);
    if (box.empty()) continue;
    Window w;
    w.pub = v.update_pub;
    w.raster = map.exportScale(0, box, wavog::Aggregation::kMean);
    w.full = v.full;
    out.push_back(std::move(w));
  }
  return out;
}

void VehicleWindows::publish(const std::vector<Window>& windows, const wavog::GridValues& values,
                             const std::string& frame, const ros::Time& stamp) {
  for (const Window& w : windows) {
    w.pub.publish(wavog_ros::toOccupancyGridMsg(w.raster, values, frame, stamp));
  }
}

void VehicleWindows::publishUpdates(const std::vector<Window>& updates,
                                    const wavog::GridValues& values, const std::string& frame,
                                    const ros::Time& stamp) {
  for (const Window& w : updates) {
    w.pub.publish(wavog_ros::toOccupancyGridUpdateMsg(w.raster, w.full.min_x, w.full.min_y, values,
                                                      frame, stamp));
  }
}

}  // namespace wavog_fleet
