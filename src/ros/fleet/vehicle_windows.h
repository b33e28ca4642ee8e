// VehicleWindows: the fleet map back to each vehicle (issue 36). Per vehicle of fleet_vehicles,
// the finest layer of the fleet node's map in a square of half-width fleet_window (m) around the
// sensor position of the vehicle's latest integrated scan (windowCells: always the same number of
// cells), on <ns>/fleet_map (OccupancyGrid,
// latched; at each full publication) and the changed part of it on <ns>/fleet_map_updates
// (OccupancyGridUpdate; at update_rate), so that a vehicle's planner sees what the others saw
// around it. Nothing is read or sent for a vehicle without subscribers or without a scan yet.
// Reads happen under the mapper's lock (as MapPublisher); publish*() run without it.
#ifndef WAVOG_MAPPING_SRC_ROS_FLEET_VEHICLE_WINDOWS_H_
#define WAVOG_MAPPING_SRC_ROS_FLEET_VEHICLE_WINDOWS_H_

#include <ros/ros.h>

#include <string>
#include <vector>

#include "../map_publisher.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog_fleet {

/// The window of half-width `half_width` (m) around (x, y): the cell holding (x, y) and
/// round(half_width / resolution) cells on each side, so 2 round(half_width / resolution) + 1
/// cells square wherever (x, y) falls in its cell (issue 42: rounding each edge on its own gave
/// 160, 161 or 162 cells for 161). Empty when (x, y) is not a number.
wavog::CellBox windowCells(const wavog::WaveletMap& map, double x, double y, double half_width);

class VehicleWindows {
 public:
  /// The latest position (map frame, m) of vehicle i of the list; false when it has none yet.
  using PositionFn = std::function<bool(std::size_t, double*, double*)>;

  /// Advertises <ns>/fleet_map and <ns>/fleet_map_updates (relative to `nh`) for each of
  /// `vehicles`; `half_width` (m) > 0.
  VehicleWindows(ros::NodeHandle nh, const std::vector<std::string>& vehicles, double half_width);

  /// A scan changed the map inside `box` (caller's lock).
  void touched(const wavog_ros::MapBox& box) { dirty_.add(box); }

  struct Window {
    ros::Publisher pub;
    wavog::Raster raster;
    wavog::CellBox full;  ///< updates: the window the raster updates
  };
  /// The windows of the vehicles with subscribers and a position (caller's lock).
  std::vector<Window> readLocked(const wavog::WaveletMap& map, const PositionFn& position);
  /// The part of each vehicle's last window changed since the previous call (caller's lock).
  std::vector<Window> readUpdatesLocked(const wavog::WaveletMap& map);
  /// Publish what the reads returned, with the mapper's grid values (no lock needed).
  static void publish(const std::vector<Window>& windows, const wavog::GridValues& values,
                      const std::string& frame, const ros::Time& stamp);
  static void publishUpdates(const std::vector<Window>& updates, const wavog::GridValues& values,
                             const std::string& frame, const ros::Time& stamp);

 private:
  struct Vehicle {
    ros::Publisher map_pub, update_pub;
    bool have_full = false;
    wavog::CellBox full;  ///< scale-0 box of the last fleet_map
  };
  double half_width_;
  std::vector<Vehicle> vehicles_;
  wavog_ros::DirtyRegion dirty_;
};

}  // namespace wavog_fleet

#endif  // WAVOG_MAPPING_SRC_ROS_FLEET_VEHICLE_WINDOWS_H_
