// Comparing two maps' rasters of one box bit for bit, shared by the fleet's tests
// (test_fleet_merge.cpp, test_fleet_system.cpp, test_fleet_shards.cpp, test_fleet_lagging.cpp).
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

/// The finest rasters of maps `a` and `b` over their bounds, when both hold cells and their bounds
/// are the same (else false).
inline bool finestRasters(const wavog::WaveletMap& a, const wavog::WaveletMap& b, wavog::Raster* ra,
                          wavog::Raster* rb) {
  wavog::CellBox ba, bb;
  if (!a.bounds(0, &ba) || !b.bounds(0, &bb)) return false;
  if (ba.min_x != bb.min_x || ba.min_y != bb.min_y || ba.max_x != bb.max_x ||
      ba.max_y != bb.max_y) {
    return false;
  }
  *ra = a.exportScale(0, ba, wavog::Aggregation::kMean);
  *rb = b.exportScale(0, bb, wavog::Aggregation::kMean);
  return true;
}

/// Known cells of `r`.
inline std::size_t knownCells(const wavog::Raster& r) {
  std::size_t known = 0;
  for (std::uint8_t k : r.known) known += k;
  return known;
}

}  // namespace map_compare

#endif  // WAVOG_MAPPING_TEST_ROS_MAP_COMPARE_H_
