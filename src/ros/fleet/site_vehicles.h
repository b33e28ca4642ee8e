// The site's view of its vehicles (issue 36), from every region shard's latest FleetStatus: which
// vehicles are outside every region now, and how many scans no shard mapped. Each shard counts the
// scans of a vehicle that reached none of its blocks (VehicleStatus.outside_region); a scan that
// reached no shard is counted by all of them, so per vehicle the smallest count over the shards is
// an upper bound on the scans mapped by none (exact while the vehicle stays outside every region).
// No roscore needed.
#ifndef WAVOG_MAPPING_SRC_ROS_FLEET_SITE_VEHICLES_H_
#define WAVOG_MAPPING_SRC_ROS_FLEET_SITE_VEHICLES_H_

#include <cstdint>
#include <string>
#include <vector>

#include "wavog_mapping/FleetStatus.h"

namespace wavog_fleet {

struct OutsideVehicle {
  std::string vehicle;
  std::string per_shard;  ///< " <shard>: <outside_region>" for each shard
};

struct SiteVehicles {
  bool complete = false;                ///< every shard has reported; else the rest is empty
  std::vector<OutsideVehicle> outside;  ///< fresh vehicles whose latest scan reached no shard
  std::uint64_t scans_mapped_by_none_max = 0;  ///< sum over vehicles of the smallest count
};

/// `statuses[i]` is shard `shards[i]`'s latest ~fleet_status (null: not heard from yet). A vehicle
/// is outside every region when every shard lists it fresh (not stale, something integrated) and
/// none says its latest scan reached its region.
SiteVehicles summariseVehicles(const std::vector<wavog_mapping::FleetStatus::ConstPtr>& statuses,
                               const std::vector<std::string>& shards);

}  // namespace wavog_fleet

#endif  // WAVOG_MAPPING_SRC_ROS_FLEET_SITE_VEHICLES_H_
