// ShardLives and summariseVehicles (see site_vehicles.h).
#include "site_vehicles.h"

#include <algorithm>
#include <limits>
#include <map>

#include "stream_index.h"

namespace wavog_fleet {
namespace {

ShardLives::Lifelong thisLife(const wavog_mapping::VehicleStatus& v) {
  ShardLives::Lifelong l;
  l.seen = saturatingAdd(v.received, v.lost);
  l.mapped = v.integrated - std::min(v.outside_region, v.integrated);
  return l;
}

}  // namespace

void ShardLives::add(std::size_t shard, const wavog_mapping::FleetStatus& status) {
  if (shard >= counts_.size()) return;
  std::map<std::string, Count>& counts = counts_[shard];
  bool restarted = false;
  for (const auto& v : status.vehicles) {
    auto it = counts.find(v.vehicle);
    if (it == counts.end()) continue;
    const wavog_mapping::VehicleStatus& last = it->second.last;
    restarted = restarted || v.received < last.received || v.lost < last.lost ||
                v.integrated < last.integrated || v.outside_region < last.outside_region;
  }
  if (restarted) {
    ++restarts_[shard];
    for (auto& kv : counts) {
      const Lifelong l = thisLife(kv.second.last);
      kv.second.before.seen = saturatingAdd(kv.second.before.seen, l.seen);
      kv.second.before.mapped = saturatingAdd(kv.second.before.mapped, l.mapped);
      kv.second.last = wavog_mapping::VehicleStatus();
    }
  }
  for (const auto& v : status.vehicles) counts[v.vehicle].last = v;
}

ShardLives::Lifelong ShardLives::get(std::size_t shard, const std::string& vehicle) const {
  Lifelong l;
  if (shard >= counts_.size()) return l;
  auto it = counts_[shard].find(vehicle);
  if (it == counts_[shard].end()) return l;
  const Lifelong now = thisLife(it->second.last);
  l.seen = saturatingAdd(it->second.before.seen, now.seen);
  l.mapped = saturatingAdd(it->second.before.mapped, now.mapped);
  return l;
}

SiteVehicles summariseVehicles(const std::vector<wavog_mapping::FleetStatus::ConstPtr>& statuses,
                               const std::vector<std::string>& shards, const ShardLives& lives) {
  SiteVehicles site;
  for (const auto& s : statuses) {
    if (!s) return site;
  }
  struct Seen {
    std::size_t listed = 0, integrated = 0, fresh = 0, in_region = 0;
    bool one_last_stamp = true;
    ros::Time last_stamp;
    std::uint64_t sent = 0;  // the most scans a shard saw over its lives
    std::string per_shard;
  };
  std::map<std::string, Seen> vehicles;
  for (std::size_t i = 0; i < statuses.size(); ++i) {
    for (const auto& v : statuses[i]->vehicles) {
      Seen& seen = vehicles[v.vehicle];
      if (seen.listed > 0 && v.last_stamp != seen.last_stamp) seen.one_last_stamp = false;
      seen.last_stamp = v.last_stamp;
      ++seen.listed;
      seen.sent = std::max(seen.sent, lives.get(i, v.vehicle).seen);
      seen.per_shard += " " + (i < shards.size() ? shards[i] : std::to_string(i)) + ": " +
                        std::to_string(v.outside_region);
      if (v.integrated == 0) continue;
      ++seen.integrated;
      seen.fresh += v.stale ? 0 : 1;
      seen.in_region += v.in_region ? 1 : 0;
    }
  }
  site.complete = true;
  for (const auto& kv : vehicles) {
    const Seen& seen = kv.second;
    if (seen.listed != statuses.size()) continue;  // a vehicle some shard does not follow
    std::uint64_t fewest = std::numeric_limits<std::uint64_t>::max();
    for (std::size_t i = 0; i < statuses.size(); ++i) {
      const std::uint64_t mapped = lives.get(i, kv.first).mapped;
      fewest = std::min(fewest, seen.sent - std::min(seen.sent, mapped));
    }
    site.scans_mapped_by_none_max = saturatingAdd(site.scans_mapped_by_none_max, fewest);
    if (seen.integrated != statuses.size() || seen.in_region != 0) continue;
    const bool silent = seen.fresh == 0 && seen.one_last_stamp;
    if (seen.fresh == statuses.size() || silent) {
      site.outside.push_back({kv.first, seen.per_shard, silent});
    }
  }
  return site;
}

SiteVehicles summariseVehicles(const std::vector<wavog_mapping::FleetStatus::ConstPtr>& statuses,
                               const std::vector<std::string>& shards) {
  ShardLives lives(statuses.size());
  for (std::size_t i = 0; i < statuses.size(); ++i) {
    if (statuses[i]) lives.add(i, *statuses[i]);
  }
  return summariseVehicles(statuses, shards, lives);
}

}  // namespace wavog_fleet
