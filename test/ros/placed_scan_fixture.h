// A well-formed PlacedScan shared by the fleet's tests without a master (test_fleet_merge.cpp,
// test_fleet_intake.cpp): one the fleet node's checks (checkPlacedScan) accept.
#ifndef WAVOG_MAPPING_TEST_ROS_PLACED_SCAN_FIXTURE_H_
#define WAVOG_MAPPING_TEST_ROS_PLACED_SCAN_FIXTURE_H_

#include <gtest/gtest.h>
#include <ros/time.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "fleet/placed_scan.h"
#include "fleet/range_codec.h"
#include "wavog_mapping/PlacedScan.h"
#include "wavog_mapping/core/params.h"
#include "wavog_mapping/core/types.h"

namespace placed_scan_fixture {

/// Vehicle "v1" (input /v1/scan, map frame "map"), stamped 100 s, its stream index `index`: 181
/// beams of 5 m over a half turn, placed at (1, 2, 0.5) without motion compensation. `codes`:
/// version 2 (the ranges as 16-bit codes, the encoding checked), else version 1 (float32 ranges).
inline wavog_mapping::PlacedScan goodScan(std::uint64_t index = 0, bool codes = false) {
  const std::vector<float> ranges(181, 5.0f);
  wavog::ScanView view;
  view.ranges = ranges.data();
  view.count = ranges.size();
  view.angle_min = -M_PI / 2;
  view.angle_increment = M_PI / 180;
  view.range_min = 0.1;
  view.range_max = 80.0;
  wavog_mapping::PlacedScan m;
  wavog_fleet::RangeCodec codec;
  if (codes) EXPECT_TRUE(codec.encode(view, wavog::MapParams{}));
  wavog_fleet::fillPlacedScan(ros::Time(100.0), "map", "v1", "/v1/scan", index,
                              wavog::Pose2{1, 2, 0.5}, view, false, wavog::Pose2{1, 2, 0.5},
                              wavog::Pose2{1, 2, 0.5}, &m, codes ? &codec : nullptr);
  return m;
}

}  // namespace placed_scan_fixture

#endif  // WAVOG_MAPPING_TEST_ROS_PLACED_SCAN_FIXTURE_H_
