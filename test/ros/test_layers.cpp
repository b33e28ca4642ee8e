// What a layer publishes without a roscore (issue 41): a whole layer too large for one message
// falls back to the square around the robot (readOccupancy), the coarser layers stay whole while
// they fit; on the Freiburg campus log at 5 cm, `map` is a window and never empty.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "../../src/ros/map_publisher.h"
#include "fan_scan.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/io/carmen_reader.h"
#include "wavog_mapping/ros/config.h"
#include "wavog_mapping/ros/conversions.h"

namespace {

using wavog_ros::LayerSize;

double cells(const wavog::CellBox& b) {
  return static_cast<double>(b.width()) * static_cast<double>(b.height());
}

bool holds(const wavog::Raster& r, double x, double y) {
  return x >= r.originX() && y >= r.originY() &&
         x < r.originX() + static_cast<double>(r.box.width()) * r.cell_size &&
         y < r.originY() + static_cast<double>(r.box.height()) * r.cell_size;
}

using fan_scan::scanAt;

// Two rooms 600 m apart at 2 cm: 30,000 x 150 cells at scale 0 fit, 60,000 x 60,000 would not.
TEST(Layers, TooLargeWholeLayerIsTheWindowAroundTheRobot) {
  wavog::MapParams p = wavog::MapParams::defaultsFor(wavog::PolicyType::kForget);
  p.grid.resolution = 0.02;
  p.grid.block_levels = 6;
  wavog::WaveletMap map(p);
  scanAt(&map, -300.0, -300.0);
  scanAt(&map, 300.0, 300.0);
  wavog_ros::RosParams rp;  // publish_window 0: the whole map
  wavog::Raster r;
  std::string refused, windowed;
  ASSERT_EQ(wavog_ros::readOccupancy(map, 0, rp, 300.0, 300.0, &r, &refused, &windowed),
            LayerSize::kOk);
  EXPECT_TRUE(refused.empty()) << refused;
  EXPECT_FALSE(windowed.empty());
  EXPECT_FALSE(r.box.empty());
  EXPECT_LE(cells(r.box), wavog_ros::kMaxLayerCells);
  EXPECT_TRUE(holds(r, 300.0, 300.0));
  EXPECT_FALSE(holds(r, -300.0, -300.0));
  // Around the other room, that room.
  ASSERT_EQ(wavog_ros::readOccupancy(map, 0, rp, -300.0, -300.0, &r, &refused, &windowed),
            LayerSize::kOk);
  EXPECT_TRUE(holds(r, -300.0, -300.0));
  // Scale 4 (32 cm) holds both rooms whole: no window.
  windowed.clear();
  ASSERT_EQ(wavog_ros::readOccupancy(map, 4, rp, 300.0, 300.0, &r, &refused, &windowed),
            LayerSize::kOk);
  EXPECT_TRUE(windowed.empty()) << windowed;
  EXPECT_TRUE(holds(r, -300.0, -300.0));
  EXPECT_TRUE(holds(r, 300.0, 300.0));
  // A publish_window the user chose is never replaced: too large, refused.
  rp.publish_window = 1e6;
  windowed.clear();
  EXPECT_EQ(wavog_ros::readOccupancy(map, 0, rp, 0.0, 0.0, &r, &refused, &windowed),
            LayerSize::kTooLarge);
  EXPECT_TRUE(r.box.empty());
  EXPECT_FALSE(refused.empty());
  EXPECT_TRUE(windowed.empty());
}

// The campus log at the default 5 cm: the whole `map` is beyond 2^24 cells; it is published as
// the square around the last scan, never as nothing, and the coarse layers stay whole.
TEST(Layers, RealDataCampusAtFiveCentimetresHasAMap) {
  const char* env = std::getenv("WAVOG_DATA_DIR");
  ASSERT_NE(env, nullptr) << "WAVOG_DATA_DIR (set by ctest)";
  const auto scans = wavog::readCarmenLog(std::string(env) + "/fr-campus-corrected.log.gz");
  ASSERT_GT(scans.size(), 1000u);
  const wavog_ros::Config config;  // the node's defaults: 5 cm, forget
  ASSERT_DOUBLE_EQ(config.map.grid.resolution, 0.05);
  wavog::WaveletMap map(config.map);
  for (const auto& s : scans) map.integrate(s.laser_pose, s.view());
  const wavog::Pose2 last = scans.back().laser_pose;
  wavog::CellBox whole;
  ASSERT_EQ(wavog_ros::layerBox(map, 0, 0.0, 0.0, 0.0, &whole), LayerSize::kTooLarge);
  wavog::Raster r;
  std::string refused, windowed;
  ASSERT_EQ(wavog_ros::readOccupancy(map, 0, config.ros, last.x, last.y, &r, &refused, &windowed),
            LayerSize::kOk);
  std::cout << "campus at 5 cm: the whole map " << whole.width() << " x " << whole.height()
            << " cells; map published as " << r.box.width() << " x " << r.box.height() << "\n";
  EXPECT_FALSE(windowed.empty());
  EXPECT_FALSE(r.box.empty());
  EXPECT_LE(cells(r.box), wavog_ros::kMaxLayerCells);
  EXPECT_TRUE(holds(r, last.x, last.y));
  const auto grid = wavog::toOccupancyGrid(r, config.ros.grid_values);
  std::size_t occupied = 0, free = 0;
  for (auto v : grid) {
    occupied += v == 100;
    free += v == 0;
  }
  EXPECT_GT(occupied, 1000u);
  EXPECT_GT(free, 100000u);
  for (int s : config.ros.publish_scales) {
    windowed.clear();
    ASSERT_EQ(wavog_ros::readOccupancy(map, s, config.ros, last.x, last.y, &r, &refused, &windowed),
              LayerSize::kOk)
        << "scale " << s;
    EXPECT_TRUE(windowed.empty()) << windowed;
  }
}

}  // namespace
