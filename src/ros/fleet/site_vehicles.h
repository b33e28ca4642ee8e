// The site's view of its vehicles (issue 36), from every region shard's FleetStatus: which
// vehicles are outside every region, and how many scans no shard mapped.
//
// Scans mapped by none, per vehicle: a scan is mapped by shard i when i integrated it and it
// reached i's region; VehicleStatus gives, per life of the shard (its counters start at 0 when it
// restarts), the scans the stream carried (received + lost) and those it mapped (integrated -
// outside_region). ShardLives adds each shard's lives up (a counter below its previous value is a
// restart), so a shard's lost scans, refused scans and the scans sent while it was down count as
// not mapped by it. The scans the vehicle sent are at least the most any shard saw over its lives;
// per vehicle, that minus what a shard mapped, smallest over the shards, is an upper bound on the
// scans mapped by none (exact while the vehicle stays outside every region and no scan is lost).
// Not counted: scans sent while no shard ran at all. No roscore needed.
#ifndef WAVOG_MAPPING_SRC_ROS_FLEET_SITE_VEHICLES_H_
#define WAVOG_MAPPING_SRC_ROS_FLEET_SITE_VEHICLES_H_

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "wavog_mapping/FleetStatus.h"

namespace wavog_fleet {

/// Each shard's per-vehicle counters added up over the shard's lives (restarts).
class ShardLives {
 public:
  explicit ShardLives(std::size_t shards) : counts_(shards), restarts_(shards, 0) {}

  /// Shard `shard`'s latest status. A vehicle whose received, lost, integrated or outside_region
  /// count is below the previous status's means the shard restarted: the previous life's counts
  /// are kept and the new life's added to them. Out-of-range shards are ignored.
  void add(std::size_t shard, const wavog_mapping::FleetStatus& status);

  struct Lifelong {
    std::uint64_t seen = 0;    ///< received + lost, over the shard's lives (saturating)
    std::uint64_t mapped = 0;  ///< integrated - outside_region, over the shard's lives
  };
  /// `vehicle`'s counts in `shard` over its lives (zero when never listed).
  Lifelong get(std::size_t shard, const std::string& vehicle) const;
  /// Restarts detected for `shard`.
  std::uint64_t restarts(std::size_t shard) const {
    return shard < restarts_.size() ? restarts_[shard] : 0;
  }

 private:
  struct Count {
    wavog_mapping::VehicleStatus last;  ///< the latest status's counters (this life)
    Lifelong before;                    ///< the previous lives' sums
  };
  std::vector<std::map<std::string, Count>> counts_;
  std::vector<std::uint64_t> restarts_;
};

struct OutsideVehicle {
  std::string vehicle;
  std::string per_shard;  ///< " <shard>: <outside_region>" for each shard
  bool silent = false;    ///< stale in every shard: its last scan reached no shard
};

struct SiteVehicles {
  bool complete = false;                ///< every shard has reported; else the rest is empty
  std::vector<OutsideVehicle> outside;  ///< vehicles whose latest scan reached no shard
  std::uint64_t scans_mapped_by_none_max = 0;  ///< upper bound, summed over vehicles (saturates)
};

/// `statuses[i]` is shard `shards[i]`'s latest ~fleet_status (null: not heard from yet), `lives`
/// every status received so far (ShardLives::add). A vehicle is outside every region when every
/// shard lists it with a scan integrated, none says its latest scan reached its region, and it is
/// fresh (not stale) in every shard, or stale in every shard (silent: its last scan, the same one
/// in every shard, reached none; it stays listed). A vehicle fresh in one shard and stale in
/// another is not named (the stale shard's view is older).
SiteVehicles summariseVehicles(const std::vector<wavog_mapping::FleetStatus::ConstPtr>& statuses,
                               const std::vector<std::string>& shards, const ShardLives& lives);

/// As above with one life per shard: its latest status only.
SiteVehicles summariseVehicles(const std::vector<wavog_mapping::FleetStatus::ConstPtr>& statuses,
                               const std::vector<std::string>& shards);

}  // namespace wavog_fleet

#endif  // WAVOG_MAPPING_SRC_ROS_FLEET_SITE_VEHICLES_H_
