// MappingRos: the one class behind the nodelet and the node. Subscribes to 1-4 LaserScan topics
// through tf2 MessageFilters, integrates every scan into one wavog::WaveletMap and publishes the
// multiscale OccupancyGrid layers, map_metadata, map_updates, ~status and /diagnostics on timers;
// serves ~reset, ~clear_region, ~save_map, ~flush, dynamic_map; dynamic_reconfigure for the
// policy, the publish rate and the scales.
// Thread-safety: callbacks may run on several threads (MT node handles); ONE mutex (mutex_) guards
// the map, the counters and everything else they share; tf2's buffer locks itself.
#ifndef WAVOG_MAPPING_ROS_MAPPING_ROS_H_
#define WAVOG_MAPPING_ROS_MAPPING_ROS_H_

#include <ros/node_handle.h>

#include <memory>

namespace wavog_ros {

/// What a MappingRos maps from: LaserScans and tf (a vehicle's mapper), or the PlacedScan
/// streams of the vehicles listed in fleet_vehicles (wavog_fleet; src/ros/fleet/).
enum class MapperRole { kMapper, kFleet };

class MappingRos {
 public:
  /// Reads the configuration from `pnh` (one loader, config.h), loads map_file, subscribes to the
  /// inputs (topics relative to `nh`) and starts the timers. Throws std::invalid_argument naming
  /// the bad parameter and its range, or std::runtime_error for an unreadable map_file.
  MappingRos(const ros::NodeHandle& nh, const ros::NodeHandle& pnh,
             MapperRole role = MapperRole::kMapper);
  ~MappingRos();
  MappingRos(const MappingRos&) = delete;
  MappingRos& operator=(const MappingRos&) = delete;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace wavog_ros

#endif  // WAVOG_MAPPING_ROS_MAPPING_ROS_H_
