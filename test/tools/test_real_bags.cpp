// Rostests of the third-party bags in ../shared/data/bags (issue 27): each played through
// launch/playback.launch with the arguments of that directory's README, as a user would. What is
// checked comes from the private parameters of the <test> (see test/tools/real_bag_*.test):
//   bag                       the bag (absolute path)
//   fixed_frame               the map frame (the bag's /tf must start from it); scans stamped
//                             before the bag's tf tree is complete cannot be placed
//   min_integrated            at least this many scans integrated
//   all_after_first_tf        every received scan stamped after the first tf is integrated
//   every_scan_mismatched     every scan's range count disagrees with its angles (counted)
//   min_absurd_pose           at least this many scans refused as absurd_pose
//   max_map_m                 the published map is at most this wide and high (no scan far away)
//   min_occupied              at least this many occupied cells in /map (default 100)
//   min_wall_share            share of occupied cells within 2 cells of a straight wall (RANSAC)
//   status_after_end          ~status read by a new subscriber after the bag's end (latched)
#include <gtest/gtest.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <cstdio>
#include <iostream>
#include <mutex>
#include <random>
#include <string>
#include <vector>

#include "mapper_listener.h"
#include "wavog_mapping/MapperStatus.h"

namespace {

constexpr double kWaitSeconds = 150.0;  // wall time for the bag and the end flush
constexpr int kOccupied = 65;           // map_server's occupied threshold (0..100)

struct BagFacts {
  std::uint64_t scans = 0;
  std::uint64_t before_first_tf = 0;  ///< scans stamped before the bag's tf tree is complete
  double first_tf = 0.0;              ///< the latest of the first stamps of its frames
};

BagFacts readBag(const std::string& path, const std::string& fixed_frame) {
  BagFacts f;
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  std::vector<double> stamps;
  std::map<std::string, double> first;  // per child frame, its first stamp
  bool from_fixed = false;
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (const auto tf = m.instantiate<tf2_msgs::TFMessage>()) {
      for (const auto& t : tf->transforms) {
        from_fixed = from_fixed || t.header.frame_id == fixed_frame;
        const auto it = first.emplace(t.child_frame_id, t.header.stamp.toSec()).first;
        it->second = std::min(it->second, t.header.stamp.toSec());
      }
    } else if (const auto scan = m.instantiate<sensor_msgs::LaserScan>()) {
      stamps.push_back(scan->header.stamp.toSec());
    }
  }
  EXPECT_TRUE(from_fixed) << "no tf from '" << fixed_frame << "' in the bag";
  // The tree is complete (every frame has its first transform) from the latest of them.
  f.first_tf = 0.0;
  for (const auto& kv : first) f.first_tf = std::max(f.first_tf, kv.second);
  f.scans = stamps.size();
  for (const double s : stamps) f.before_first_tf += s < f.first_tf ? 1 : 0;
  return f;
}

struct Point {
  double x, y;
};

/// Share of the occupied cells within `tol` of one of at most `max_walls` straight walls found
/// one after the other by RANSAC (each at least `min_cells` cells), in cells.
double wallShare(const nav_msgs::OccupancyGrid& map, int max_walls, std::size_t min_cells,
                 double tol) {
  std::vector<Point> pts;
  for (std::uint32_t y = 0; y < map.info.height; ++y) {
    for (std::uint32_t x = 0; x < map.info.width; ++x) {
      if (map.data[y * map.info.width + x] >= kOccupied) pts.push_back({double(x), double(y)});
    }
  }
  const std::size_t total = pts.size();
  if (total == 0) return 0.0;
  std::mt19937 rng(27);
  std::size_t on_walls = 0;
  for (int w = 0; w < max_walls && pts.size() >= min_cells; ++w) {
    std::uniform_int_distribution<std::size_t> pick(0, pts.size() - 1);
    std::vector<bool> best;
    std::size_t best_n = 0;
    for (int it = 0; it < 2000; ++it) {
      const Point a = pts[pick(rng)], b = pts[pick(rng)];
      const double dx = b.x - a.x, dy = b.y - a.y, len = std::hypot(dx, dy);
      if (len < 10.0) continue;  // two cells far apart define the line
      std::vector<bool> in(pts.size());
      std::size_t n = 0;
      for (std::size_t i = 0; i < pts.size(); ++i) {
        in[i] = std::abs((pts[i].x - a.x) * dy - (pts[i].y - a.y) * dx) / len <= tol;
        n += in[i];
      }
      if (n > best_n) best_n = n, best = std::move(in);
    }
    if (best_n < min_cells) break;
    on_walls += best_n;
    std::vector<Point> rest;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      if (!best[i]) rest.push_back(pts[i]);
    }
    pts.swap(rest);
  }
  return static_cast<double>(on_walls) / static_cast<double>(total);
}

TEST(RealBags, MappedAsTheReadmeSays) {
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  std::string path, fixed_frame;
  ASSERT_TRUE(pnh.getParam("bag", path));
  ASSERT_TRUE(pnh.getParam("fixed_frame", fixed_frame));
  const BagFacts bag = readBag(path, fixed_frame);
  ASSERT_GT(bag.scans, 100u);
  const int min_integrated = pnh.param("min_integrated", 0);

  wavog_test::MapperListener mapper(nh);
  ros::AsyncSpinner spinner(1);
  spinner.start();

  // The bag has ended once nothing has changed in the status for a while (the idle flush then
  // publishes it once more; idle_timeout 2 s of wall time).
  const ros::WallTime t_start = ros::WallTime::now();
  const ros::WallTime deadline = t_start + ros::WallDuration(kWaitSeconds);
  wavog_mapping::InputStatus input;
  std::uint64_t last_accounted = 0;
  ros::WallTime last_change = ros::WallTime::now();
  while (ros::ok() && ros::WallTime::now() < deadline) {
    mapper.firstInput(&input);
    const std::uint64_t accounted = input.received + input.integrated;
    if (accounted != last_accounted) {
      last_accounted = accounted;
      last_change = ros::WallTime::now();
    }
    if (input.received > 0 && (ros::WallTime::now() - last_change).toSec() > 8.0) break;
    ros::WallDuration(0.2).sleep();
  }
  std::printf("[real bag] %s: %llu scans in the bag (%llu before the tf tree from '%s' is complete); wall "
              "time %.1f s\n",
              path.c_str(), static_cast<unsigned long long>(bag.scans),
              static_cast<unsigned long long>(bag.before_first_tf), fixed_frame.c_str(),
              (ros::WallTime::now() - t_start).toSec());
  std::cout << "[real bag] final status of the input:\n" << input << std::endl;
  ASSERT_GT(input.received, 0u);
  EXPECT_LE(input.received, bag.scans);
  EXPECT_GE(input.integrated, static_cast<std::uint64_t>(min_integrated)) << input;
  EXPECT_EQ(input.dropped_bad_angles + input.dropped_bad_geometry + input.dropped_out_of_extent +
                input.dropped_empty + input.dropped_bad_frame + input.dropped_exception,
            0u)
      << input;
  if (pnh.param("all_after_first_tf", false)) {
    // Only scans stamped before the first tf may be missing (the bag plays from its start).
    EXPECT_GE(input.integrated + bag.before_first_tf, input.received) << input;
  }
  if (pnh.param("every_scan_mismatched", false)) {
    EXPECT_EQ(input.beam_count_mismatches, input.received) << input;
  } else {
    EXPECT_EQ(input.beam_count_mismatches, 0u) << input;
  }
  const int min_absurd = pnh.param("min_absurd_pose", 0);
  if (min_absurd > 0) {
    EXPECT_GE(input.dropped_absurd_pose, static_cast<std::uint64_t>(min_absurd)) << input;
  } else {
    EXPECT_EQ(input.dropped_absurd_pose, 0u) << input;
  }

  const nav_msgs::OccupancyGrid::ConstPtr map = mapper.map();
  ASSERT_TRUE(map != nullptr) << "no /map received";
  const double width_m = map->info.width * map->info.resolution;
  const double height_m = map->info.height * map->info.resolution;
  std::printf("[real bag] map %u x %u cells (%.1f x %.1f m)\n", map->info.width, map->info.height,
              width_m, height_m);
  const double max_map_m = pnh.param("max_map_m", 50.0);
  EXPECT_LE(width_m, max_map_m);
  EXPECT_LE(height_m, max_map_m);
  const double min_wall_share = pnh.param("min_wall_share", 0.0);
  std::uint64_t occupied = 0;
  for (const std::int8_t v : map->data) occupied += v >= kOccupied ? 1 : 0;
  EXPECT_GE(occupied, static_cast<std::uint64_t>(pnh.param("min_occupied", 100)));
  if (min_wall_share > 0.0) {
    const double share = wallShare(*map, 12, 20, 2.0);
    std::printf("[real bag] occupied cells within 2 cells of one of 12 RANSAC walls: %.3f\n",
                share);
    EXPECT_GE(share, min_wall_share);
  }

  if (pnh.param("status_after_end", false)) {
    // As `rostopic echo -n 1 /wavog_mapping/status` after the bag: a new subscriber, the bag's
    // clock stopped, receives the latched status at once, with the final counters.
    mapper.stopStatus();
    std::mutex m;
    wavog_mapping::MapperStatus::ConstPtr late;
    ros::NodeHandle late_nh;
    const boost::function<void(const wavog_mapping::MapperStatus::ConstPtr&)> on_late =
        [&](const wavog_mapping::MapperStatus::ConstPtr& s) {
          std::lock_guard<std::mutex> lock(m);
          late = s;
        };
    ros::Subscriber late_sub = late_nh.subscribe("/wavog_mapping/status", 1, on_late);
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(5.0);
    bool got = false;
    while (!got && ros::WallTime::now() < end) {
      ros::WallDuration(0.05).sleep();
      std::lock_guard<std::mutex> lock(m);
      got = late != nullptr;
    }
    ASSERT_TRUE(got) << "no latched ~status after the bag's end";
    std::lock_guard<std::mutex> lock(m);
    ASSERT_EQ(late->inputs.size(), 1u);
    EXPECT_EQ(late->inputs[0].integrated, input.integrated);
    EXPECT_EQ(late->inputs[0].received, input.received);
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_real_bags");
  return RUN_ALL_TESTS();
}
