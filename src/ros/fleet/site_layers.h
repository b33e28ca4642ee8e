// Site layers (issue 36): the coarse layers of a site's region shards put together. Each shard
// (wavog_fleet with fleet_region) publishes map_scale_<s> cut to the cells it observed, all of them
// inside its region; regions do not overlap and a scale-s cell (s <= block_levels) lies in one
// block, so the site layer is every shard's known cells on one grid: equal, cell for cell, to the
// map_scale_<s> of one fleet node without a region fed the same streams.
#ifndef WAVOG_MAPPING_SRC_ROS_FLEET_SITE_LAYERS_H_
#define WAVOG_MAPPING_SRC_ROS_FLEET_SITE_LAYERS_H_

#include <nav_msgs/OccupancyGrid.h>

#include <cstdint>
#include <string>
#include <vector>

namespace wavog_fleet {

/// Why a site layer was not assembled (each counted by wavog_site).
enum class SiteRefusal {
  kNone,          ///< assembled
  kNothingKnown,  ///< no shard has published a known cell yet (not an error)
  kBadLayer,      ///< a shard's layer is malformed: data size, resolution, rotation, a value
  kMismatch,      ///< the shards' layers differ in frame, resolution or cell lattice
  kTooLarge,      ///< the grid holding every shard's cells would exceed max_cells
};

/// The largest site layer wavog_site assembles by default (~max_cells): a mapper's own limit on
/// a published layer (2^24 cells, 16 MB).
constexpr std::uint64_t kDefaultMaxSiteCells = std::uint64_t{1} << 24;
/// The largest ~max_cells accepted (2^28 cells: 256 MB per layer).
constexpr std::uint64_t kMaxSiteCellsLimit = std::uint64_t{1} << 28;

/// Puts `parts` (the shards' layers of one scale, in one frame) together into `out`: the
/// smallest grid holding every part's known cells (-1 elsewhere), each part's known cells copied
/// (where two parts know a cell, the later one wins: overlapping regions are a configuration
/// error). The header is the oldest part's: the site layer holds every shard's map as of at least
/// that stamp. Null and empty parts are skipped. Anything but kNone leaves `out` empty and says
/// why in *why (naming the part by its index in `parts`); nothing a part holds can make it
/// allocate more than max_cells cells or write outside `out`.
SiteRefusal assembleSiteLayer(const std::vector<const nav_msgs::OccupancyGrid*>& parts,
                              std::uint64_t max_cells, nav_msgs::OccupancyGrid* out,
                              std::string* why);

}  // namespace wavog_fleet

#endif  // WAVOG_MAPPING_SRC_ROS_FLEET_SITE_LAYERS_H_
