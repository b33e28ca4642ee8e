// Comparing two maps' rasters of one box bit for bit, shared by the fleet's tests
// (test_fleet_merge.cpp, test_fleet_system.cpp, test_fleet_shards.cpp).
#ifndef WAVOG_MAPPING_TEST_ROS_MAP_COMPARE_H_
#define WAVOG_MAPPING_TEST_ROS_MAP_COMPARE_H_

#include <cstddef>
#include <cstring>

#include "wavog_mapping/core/wavelet_map.h"

namespace map_compare {

/// Cells of `a` that differ from the same cell of `b` (a raster of the same box): in being known
/// or in the bits of their log-odds.
inline std::size_t differingCells(const wavog::Raster& a, const wavog::Raster& b) {
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.log_odds.size(); ++i) {
    differ += a.known[i] != b.known[i] ||
              std::memcmp(&a.log_odds[i], &b.log_odds[i], sizeof(float)) != 0;
  }
  return differ;
}

/// Known cells of `r`.
inline std::size_t knownCells(const wavog::Raster& r) {
  std::size_t known = 0;
  for (std::uint8_t k : r.known) known += k;
  return known;
}

}  // namespace map_compare

#endif  // WAVOG_MAPPING_TEST_ROS_MAP_COMPARE_H_
