// Site layers (issue 36): the coarse layers of a site's region shards put together. Each shard
// (wavog_fleet with fleet_region) publishes map_scale_<s> cut to the cells it observed, all of them
// inside its region; regions do not overlap and a scale-s cell (s <= block_levels) lies in one
// block, so the site layer is every shard's known cells on one grid: equal, cell for cell, to the
// map_scale_<s> of one fleet node without a region fed the same streams.
#ifndef WAVOG_MAPPING_SRC_ROS_FLEET_SITE_LAYERS_H_
#define WAVOG_MAPPING_SRC_ROS_FLEET_SITE_LAYERS_H_

#include <nav_msgs/OccupancyGrid.h>

#include <string>
#include <vector>

namespace wavog_fleet {

/// Puts `parts` (the shards' layers of one scale, in one frame) together into `out`: the
/// smallest grid holding every part's known cells (-1 elsewhere), each part's known cells copied
/// (where two parts know a cell, the later one wins: overlapping regions are a configuration
/// error). The header is the oldest part's: the site layer holds every shard's map as of at least
/// that stamp. False, with *why, when the parts do not share one
/// frame, resolution and cell lattice (origins a whole number of cells apart), or none has a
/// known cell (then out is an empty grid).
bool assembleSiteLayer(const std::vector<const nav_msgs::OccupancyGrid*>& parts,
                       nav_msgs::OccupancyGrid* out, std::string* why);

}  // namespace wavog_fleet

#endif  // WAVOG_MAPPING_SRC_ROS_FLEET_SITE_LAYERS_H_
