// A fan of 100 beams returning at 3 m, taken into a map at (x, y): the small observed patch the
// layer tests (test_layers, test_node_limits) place where their boxes need one.
#ifndef WAVOG_MAPPING_TEST_ROS_FAN_SCAN_H_
#define WAVOG_MAPPING_TEST_ROS_FAN_SCAN_H_

#include <gtest/gtest.h>

#include <vector>

#include "wavog_mapping/core/wavelet_map.h"

namespace fan_scan {

inline void scanAt(wavog::WaveletMap* map, double x, double y) {
  const std::vector<float> ranges(100, 3.0f);
  wavog::ScanView v;
  v.ranges = ranges.data();
  v.count = ranges.size();
  v.angle_min = -1.5;
  v.angle_increment = 0.03;
  v.range_min = 0.1;
  v.range_max = 30.0;
  ASSERT_EQ(map->integrate(wavog::Pose2{x, y, 0.0}, v).status, wavog::ScanStatus::kOk);
}

}  // namespace fan_scan

#endif  // WAVOG_MAPPING_TEST_ROS_FAN_SCAN_H_
