// wavog_site's parameters (issue 36), read from its private namespace as XmlRpc values so that
// every bad value fails at start-up naming the parameter and its range: a string where a number
// belongs (roslaunch passes `rate:=nan` as the string "nan"), NaN, infinities, a scale that is not
// a whole number (roscpp would truncate 3.5 to 3). And the shards' regions (each shard's
// <shard>/wavog_fleet/fleet_region): overlapping regions are a configuration error the site can
// see (a cell mapped by two shards; where both know a cell the site layer takes the later one).
// No roscore needed.
#ifndef WAVOG_MAPPING_SRC_ROS_FLEET_SITE_PARAMS_H_
#define WAVOG_MAPPING_SRC_ROS_FLEET_SITE_PARAMS_H_

#include <xmlrpcpp/XmlRpcValue.h>

#include <cstdint>
#include <string>
#include <vector>

namespace wavog_fleet {

struct SiteParams {
  std::vector<std::string> shards;
  std::vector<int> scales;
  double rate = 1.0;            ///< Hz
  std::uint64_t max_cells = 0;  ///< cells of one site layer
};

/// Reads ~shards, ~scales, ~rate (default 1.0) and ~max_cells (default kDefaultMaxSiteCells) from
/// `root` (the private namespace, a struct; anything else: every key missing). Throws
/// std::invalid_argument naming the first bad parameter and its valid range.
SiteParams readSiteParams(const XmlRpc::XmlRpcValue& root);

/// A shard's region [min_x, min_y, max_x, max_y] (m) as its fleet_region parameter holds it.
struct ShardRegion {
  std::string shard;
  std::vector<double> region;  ///< empty: no region (the shard maps everything)
};

/// A fleet_region value (a list of 4 numbers, or [] for none) into *region; false if malformed.
bool readRegion(const XmlRpc::XmlRpcValue& value, std::vector<double>* region);

/// Pairs of shards whose regions overlap (an area > 0 in common; a shard without a region
/// overlaps every other), one line each: "<a> [..] and <b> [..]".
std::vector<std::string> overlappingRegions(const std::vector<ShardRegion>& regions);

}  // namespace wavog_fleet

#endif  // WAVOG_MAPPING_SRC_ROS_FLEET_SITE_PARAMS_H_
