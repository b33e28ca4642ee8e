// Pose error in the simulator (per-scan Gaussian noise and drift on the pose given to the mapper)
// and the wall figures it degrades: on a short scenario (a vehicle driving through a walled room),
// the width at half maximum across the walls grows with the pose noise under max and clamping,
// and zero noise reproduces the exact-pose evaluation bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "wavog_mapping/sim/evaluation.h"
#include "wavog_mapping/sim/laser_sim.h"
#include "wavog_mapping/sim/noise_study.h"
#include "wavog_mapping/sim/pose_noise.h"
#include "wavog_mapping/sim/wall_metrics.h"
#include "wavog_mapping/sim/world.h"

namespace wavog {
namespace sim {
namespace {

constexpr double kResolution = 0.05;
constexpr std::uint64_t kSeed = 3;

WorldObject wallObject(const std::string& name, double x0, double y0, double x1, double y1) {
  WorldObject o;
  o.name = name;
  o.kind = ObjectKind::kWall;
  o.shape = makeRect(x0, y0, x1, y1);
  return o;
}

// A 12 m x 8 m room with 0.3 m walls; one 270-degree laser on a vehicle driving 8 m along the
// room's long axis in 5 s, so every wall is seen from many vantage points.
World roomWorld() {
  World w;
  w.name = "test_room";
  w.duration = 5.0;
  w.region_min = Vec2(-1.0, -1.0);
  w.region_max = Vec2(13.0, 9.0);
  w.objects.push_back(wallObject("south", -0.3, -0.3, 12.3, 0.0));
  w.objects.push_back(wallObject("north", -0.3, 8.0, 12.3, 8.3));
  w.objects.push_back(wallObject("west", -0.3, 0.0, 0.0, 8.0));
  w.objects.push_back(wallObject("east", 12.0, 0.0, 12.3, 8.0));
  w.vehicle.footprint = makeBox(1.0, 0.6);
  w.vehicle.path.waypoints = {Waypoint{0.0, Pose2{2.0, 3.0, 0.0}},
                              Waypoint{5.0, Pose2{10.0, 5.0, 0.3}}};
  LaserParams l;
  l.name = "front";
  l.frame_id = "front_laser";
  l.topic = "front/scan";
  l.fov = 1.5 * M_PI;
  l.beams = 541;
  l.range_max = 30.0;
  l.noise_sigma = 0.01;
  l.dropout_prob = 0.0;
  w.vehicle.lasers.push_back(l);
  return w;
}

PolicyRun runFor(PolicyType type) {
  PolicyRun r;
  r.params = MapParams::defaultsFor(type);
  r.params.grid.resolution = kResolution;
  r.label = toString(type);
  return r;
}

TEST(PoseNoise, ZeroNoiseLeavesScansUntouched) {
  const World world = roomWorld();
  const std::vector<SimScan> scans = simulateAll(world, kSeed);
  PoseNoiseParams none;
  none.seed = 99;
  EXPECT_FALSE(none.enabled());
  const std::vector<SimScan> same = withPoseError(world, scans, none);
  ASSERT_EQ(same.size(), scans.size());
  for (std::size_t i = 0; i < scans.size(); ++i) {
    EXPECT_EQ(same[i].sensor_pose.x, scans[i].sensor_pose.x);
    EXPECT_EQ(same[i].sensor_pose.y, scans[i].sensor_pose.y);
    EXPECT_EQ(same[i].sensor_pose.theta, scans[i].sensor_pose.theta);
  }
}

TEST(PoseNoise, GaussianErrorHasTheConfiguredSpreadAndLasersKeepTheTruth) {
  const World world = roomWorld();
  const std::vector<SimScan> scans = simulateAll(world, kSeed);
  PoseNoiseParams p;
  p.sigma_xy_m = 0.05;
  p.sigma_yaw_rad = 0.01;
  p.seed = 5;
  const std::vector<SimScan> noisy = withPoseError(world, scans, p);
  ASSERT_EQ(noisy.size(), scans.size());
  double sx = 0, sxx = 0, st = 0, stt = 0;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    const double dx = noisy[i].vehicle_pose.x - scans[i].vehicle_pose.x;
    const double dt = wrapAngle(noisy[i].vehicle_pose.theta - scans[i].vehicle_pose.theta);
    sx += dx;
    sxx += dx * dx;
    st += dt;
    stt += dt * dt;
    // Same ranges, same truth: the lasers measured from the true pose.
    ASSERT_EQ(noisy[i].ranges, scans[i].ranges);
    ASSERT_EQ(noisy[i].true_ranges, scans[i].true_ranges);
    // The sensor pose follows the noisy vehicle pose through the mount.
    const Pose2 expected = compose(noisy[i].vehicle_pose, world.vehicle.lasers[0].mount);
    EXPECT_NEAR(noisy[i].sensor_pose.x, expected.x, 1e-12);
  }
  const double n = static_cast<double>(scans.size());  // 200 scans
  EXPECT_NEAR(sx / n, 0.0, 4 * p.sigma_xy_m / std::sqrt(n));
  EXPECT_NEAR(std::sqrt(sxx / n), p.sigma_xy_m, 0.2 * p.sigma_xy_m);
  EXPECT_NEAR(st / n, 0.0, 4 * p.sigma_yaw_rad / std::sqrt(n));
  EXPECT_NEAR(std::sqrt(stt / n), p.sigma_yaw_rad, 0.2 * p.sigma_yaw_rad);

  // Deterministic per (seed, laser, scan); another seed gives other errors.
  const Pose2 a = poseError(p, 0, 17, 1.0);
  const Pose2 b = poseError(p, 0, 17, 1.0);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.theta, b.theta);
  PoseNoiseParams q = p;
  q.seed = 6;
  EXPECT_NE(poseError(q, 0, 17, 1.0).x, a.x);
}

TEST(PoseNoise, DriftGrowsLinearlyWithTime) {
  PoseNoiseParams p;
  p.drift_x_m_per_s = 0.01;
  p.drift_yaw_rad_per_s = -0.002;
  EXPECT_TRUE(p.enabled());
  const Pose2 e = poseError(p, 0, 3, 20.0);
  EXPECT_NEAR(e.x, 0.2, 1e-12);
  EXPECT_NEAR(e.y, 0.0, 1e-12);
  EXPECT_NEAR(e.theta, -0.04, 1e-12);
  PoseNoiseParams bad;
  bad.sigma_xy_m = -1.0;
  EXPECT_EQ(bad.validate().size(), 1u);
}

// A raster with vertical walls of known widths: the profile measure must return them.
TEST(WallMetrics, HalfMaxWidthOfSyntheticWalls) {
  for (int thickness : {1, 3}) {
    Raster r;
    r.cell_size = 0.1;
    r.box = CellBox{0, 0, 40, 60};
    r.log_odds.assign(2400, -2.0f);
    r.known.assign(2400, 1);
    for (int y = 0; y < 60; ++y) {
      for (int x = 20; x < 20 + thickness; ++x)
        r.log_odds[static_cast<std::size_t>(y) * 40 + x] = 3.0f;
      for (int x = 0; x < 20; ++x) r.known[static_cast<std::size_t>(y) * 40 + x] = 0;  // behind
    }
    // Free face at x = 2.0 + thickness * 0.1, normal +x; the wall's back (x < 2) unobserved.
    std::vector<WallSample> samples;
    for (double y = 0.25; y < 6.0; y += 0.5) {
      samples.push_back(WallSample{Vec2(2.0 + thickness * 0.1 - 0.05, y), Vec2(1, 0), false});
    }
    const WallWidth w = wallWidthAtHalfMax(r, samples, WallProfileOptions());
    EXPECT_EQ(w.measured, samples.size());
    EXPECT_DOUBLE_EQ(w.mean_cells, thickness);
    // Found from the map alone, too (two-sided profiles; a 1 m disc sees a 3-cell wall as a line).
    const std::vector<WallSample> found = wallSamplesFromMap(r, WallProfileOptions(), 1.0);
    ASSERT_GE(found.size(), 2u);
    EXPECT_DOUBLE_EQ(wallWidthAtHalfMax(r, found, WallProfileOptions()).mean_cells, thickness);
  }
}

class ThickWalls : public ::testing::Test {
 protected:
  void SetUp() override {
    world_ = roomWorld();
    scans_ = simulateAll(world_, kSeed);
    events_ = findEvents(world_, scans_, kResolution);
    levels_ = parseNoiseLevels("0:0,2:0.2,5:0.5", kSeed);
    ASSERT_EQ(levels_.size(), 3u);
  }
  World world_;
  std::vector<SimScan> scans_;
  std::vector<WorldEvent> events_;
  std::vector<NoiseLevel> levels_;
};

TEST_F(ThickWalls, ZeroNoiseGivesExactlyTheExactPoseFigures) {
  const std::vector<PolicyRun> runs = {runFor(PolicyType::kMax), runFor(PolicyType::kForget)};
  const std::vector<NoiseStudyRow> rows =
      runNoiseStudy(world_, scans_, events_, runs, {levels_[0]}, EvaluationOptions(), 2);
  ASSERT_EQ(rows.size(), runs.size());
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const PolicyResult today = evaluatePolicy(world_, scans_, events_, runs[i]);
    const PolicyResult& zero = rows[i].result;
    EXPECT_EQ(zero.precision, today.precision) << runs[i].label;
    EXPECT_EQ(zero.recall, today.recall) << runs[i].label;
    EXPECT_EQ(zero.wall_distance, today.wall_distance) << runs[i].label;
    EXPECT_EQ(zero.occupied_cells, today.occupied_cells) << runs[i].label;
    EXPECT_EQ(zero.nodes, today.nodes) << runs[i].label;
    EXPECT_EQ(zero.bytes, today.bytes) << runs[i].label;
    EXPECT_EQ(zero.observed_cells, today.observed_cells) << runs[i].label;
    const WallFigures walls = wallFigures(world_, today, scans_.back().stamp);
    EXPECT_EQ(rows[i].walls.width.mean_cells, walls.width.mean_cells) << runs[i].label;
  }
}

TEST_F(ThickWalls, MaxAndClampThickenWallsAsPoseNoiseGrows) {
  const std::vector<PolicyRun> runs = {runFor(PolicyType::kMax), runFor(PolicyType::kClamp)};
  const std::vector<NoiseStudyRow> rows =
      runNoiseStudy(world_, scans_, events_, runs, levels_, EvaluationOptions(), 2);
  ASSERT_EQ(rows.size(), levels_.size() * runs.size());
  for (std::size_t r = 0; r < runs.size(); ++r) {
    double previous = 0.0;
    for (std::size_t l = 0; l < levels_.size(); ++l) {
      const NoiseStudyRow& row = rows[l * runs.size() + r];
      // The room's inner faces (about half of the faces asked for: the outer ones are never
      // seen) are measured at every level.
      EXPECT_GE(row.walls.width.measured, 60u) << row.level;
      EXPECT_GT(row.walls.width.mean_cells, previous)
          << runs[r].label << " at " << row.level << " is not thicker than at the level below";
      std::cout << runs[r].label << " at " << row.level << ": wall width "
                << row.walls.width.mean_cells << " cells, distance to the wall surface "
                << 100 * row.walls.surface_distance_m << " cm\n";
      previous = row.walls.width.mean_cells;
    }
  }
}

}  // namespace
}  // namespace sim
}  // namespace wavog
