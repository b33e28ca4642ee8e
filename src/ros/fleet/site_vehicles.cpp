// summariseVehicles (see site_vehicles.h).
#include "site_vehicles.h"

#include <algorithm>
#include <limits>
#include <map>

namespace wavog_fleet {

SiteVehicles summariseVehicles(const std::vector<wavog_mapping::FleetStatus::ConstPtr>& statuses,
                               const std::vector<std::string>& shards) {
  SiteVehicles site;
  for (const auto& s : statuses) {
    if (!s) return site;
  }
  struct Seen {
    std::size_t listed = 0, fresh = 0, in_region = 0;
    std::uint64_t min_outside = std::numeric_limits<std::uint64_t>::max();
    std::string per_shard;
  };
  std::map<std::string, Seen> vehicles;
  for (std::size_t i = 0; i < statuses.size(); ++i) {
    for (const auto& v : statuses[i]->vehicles) {
      Seen& seen = vehicles[v.vehicle];
      ++seen.listed;
      seen.min_outside = std::min(seen.min_outside, v.outside_region);
      seen.per_shard += " " + (i < shards.size() ? shards[i] : std::to_string(i)) + ": " +
                        std::to_string(v.outside_region);
      if (v.integrated == 0 || v.stale) continue;
      ++seen.fresh;
      seen.in_region += v.in_region ? 1 : 0;
    }
  }
  site.complete = true;
  for (const auto& kv : vehicles) {
    const Seen& seen = kv.second;
    if (seen.listed != statuses.size()) continue;  // a vehicle some shard does not follow
    const std::uint64_t room =
        std::numeric_limits<std::uint64_t>::max() - site.scans_mapped_by_none_max;
    site.scans_mapped_by_none_max += std::min(room, seen.min_outside);  // saturates
    if (seen.fresh == statuses.size() && seen.in_region == 0) {
      site.outside.push_back({kv.first, seen.per_shard});
    }
  }
  return site;
}

}  // namespace wavog_fleet
