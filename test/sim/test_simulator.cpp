// Simulator tests: determinism for a seed, exact ranges against analytic distances, noise and
// dropout statistics, ground-truth rasterisation, world files, and the default scenario's sanity.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "wavog_mapping/sim/ground_truth.h"
#include "wavog_mapping/sim/laser_sim.h"
#include "wavog_mapping/sim/world.h"
#include "wavog_mapping/sim/world_file.h"

namespace wavog {
namespace sim {
namespace {

constexpr std::uint64_t kSeed = 20070707;

bool sameBits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

TEST(ScanSimulator, IsDeterministicForASeed) {
  const World world = defaultWorld(2.0);
  const std::vector<SimScan> a = simulateAll(world, kSeed);
  const std::vector<SimScan> b = simulateAll(world, kSeed);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), ScanSimulator(world, kSeed).scanCount());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].stamp, b[i].stamp);
    EXPECT_EQ(a[i].laser, b[i].laser);
    EXPECT_TRUE(sameBits(a[i].ranges, b[i].ranges)) << "scan " << i;
  }
  // A scan does not depend on which scans were simulated before it.
  const ScanSimulator sim(world, kSeed);
  const SimScan& last = a.back();
  EXPECT_TRUE(sameBits(sim.simulate(last.laser, last.seq).ranges, last.ranges));
  // Another seed changes the noise, not the truth.
  const std::vector<SimScan> c = simulateAll(world, kSeed + 1);
  EXPECT_FALSE(sameBits(a[10].ranges, c[10].ranges));
  EXPECT_EQ(a[10].true_ranges, c[10].true_ranges);
}

TEST(ScanSimulator, ScansAreInTimeOrderAtEachLasersRate) {
  const World world = defaultWorld(1.0);
  const std::vector<SimScan> scans = simulateAll(world, kSeed);
  // Four lasers at 40 Hz for 1 s.
  EXPECT_EQ(scans.size(), 160u);
  for (std::size_t i = 1; i < scans.size(); ++i) EXPECT_LE(scans[i - 1].stamp, scans[i].stamp);
  for (const SimScan& s : scans) {
    EXPECT_EQ(s.ranges.size(), 361u);
    EXPECT_NEAR(s.stamp * 40.0 - static_cast<double>(s.seq), 0.25 * s.laser, 1e-9);
  }
}

TEST(RayCaster, BeamRangeEqualsAnalyticDistanceToAWall) {
  // The test world with its car gone: a wall face at x = 10 for |y| <= 10, laser at the origin.
  const World world = testWorld(/*depart_time=*/0.0, /*duration=*/0.1);
  const LaserParams& laser = world.vehicle.lasers[0];
  const SimScan scan = ScanSimulator(world, kSeed).simulate(0, 0);
  int on_wall = 0;
  for (int i = 0; i < laser.beams; ++i) {
    const double bearing = laser.angleMin() + i * laser.angleIncrement();
    const double expected = 10.0 / std::cos(bearing);
    if (std::abs(bearing) <= M_PI / 4 - 1e-9) {
      EXPECT_NEAR(scan.true_ranges[static_cast<std::size_t>(i)], expected, 1e-9) << "beam " << i;
      EXPECT_EQ(scan.ranges[static_cast<std::size_t>(i)], static_cast<float>(expected));
      ++on_wall;
    } else if (std::abs(bearing) > M_PI / 4 + 1e-9) {
      // Past the wall's ends nothing is within 80 m: no return, +inf (REP 117).
      EXPECT_TRUE(std::isinf(scan.ranges[static_cast<std::size_t>(i)])) << "beam " << i;
      EXPECT_GT(scan.ranges[static_cast<std::size_t>(i)], 0.0f);
    }
  }
  EXPECT_EQ(on_wall, 179);  // beams at -44.5 .. +44.5 deg
}

TEST(RayCaster, RangeFromAnArbitraryPoseEqualsDistanceToTheLine) {
  // A long wall along the line y = 3 (between x = -100 and 100), sensor at (1, -2) facing 30 deg.
  const RayCaster caster({makeRect(-100.0, 3.0, 100.0, 4.0)});
  const Pose2 sensor{1.0, -2.0, 30.0 * M_PI / 180.0};
  for (double bearing = -1.2; bearing <= 1.2; bearing += 0.05) {
    const double heading = sensor.theta + bearing;
    int hit = -2;
    const double r = caster.cast(sensor, bearing, 80.0, &hit);
    const double expected = 5.0 / std::sin(heading);  // distance to y = 3 along the ray
    if (std::sin(heading) > 5.0 / 80.0) {
      EXPECT_NEAR(r, expected, 1e-9) << "bearing " << bearing;
      EXPECT_EQ(hit, 0);
    } else {
      EXPECT_TRUE(std::isinf(r));
      EXPECT_EQ(hit, -1);
    }
  }
  // The nearer of two surfaces wins, whatever their order.
  const RayCaster two({makeRect(5.0, -1.0, 6.0, 1.0), makeRect(2.0, -1.0, 3.0, 1.0)});
  int hit = -1;
  EXPECT_NEAR(two.cast(Pose2{}, 0.0, 80.0, &hit), 2.0, 1e-12);
  EXPECT_EQ(hit, 1);
}

TEST(ScanSimulator, NoiseAndDropoutsMatchTheirParameters) {
  constexpr double kSigma = 0.05;
  constexpr double kDropout = 0.02;
  World world = testWorld(0.0, /*duration=*/5.0, kSigma);  // 200 scans
  world.vehicle.lasers[0].dropout_prob = kDropout;
  const std::vector<SimScan> scans = simulateAll(world, kSeed);
  double sum = 0.0, sum2 = 0.0;
  std::size_t n = 0, dropped = 0, beams = 0;
  for (const SimScan& s : scans) {
    for (std::size_t i = 0; i < s.ranges.size(); ++i) {
      ++beams;
      if (std::isnan(s.ranges[i])) {
        ++dropped;
        continue;
      }
      if (!std::isfinite(s.true_ranges[i])) {
        EXPECT_TRUE(std::isinf(s.ranges[i]));
        continue;
      }
      const double e = s.ranges[i] - s.true_ranges[i];
      sum += e;
      sum2 += e * e;
      ++n;
    }
  }
  ASSERT_GT(n, 30000u);
  const double mean = sum / n;
  const double sd = std::sqrt(sum2 / n - mean * mean);
  // Mean within 5 standard errors; sd within 5 standard errors of its estimate (sigma/sqrt(2n)),
  // both far above float rounding of ~10 m ranges (1e-6 m).
  EXPECT_NEAR(mean, 0.0, 5 * kSigma / std::sqrt(static_cast<double>(n)));
  EXPECT_NEAR(sd, kSigma, 5 * kSigma / std::sqrt(2.0 * n));
  const double rate = static_cast<double>(dropped) / beams;
  EXPECT_NEAR(rate, kDropout, 5 * std::sqrt(kDropout * (1 - kDropout) / beams));
}

TEST(Trajectory, InterpolatesAndHoldsItsEnds) {
  Trajectory traj;
  traj.waypoints = {{1.0, Pose2{0, 0, 3.0}}, {3.0, Pose2{2, 4, -3.0}}};
  const Pose2 mid = traj.at(2.0);
  EXPECT_DOUBLE_EQ(mid.x, 1.0);
  EXPECT_DOUBLE_EQ(mid.y, 2.0);
  // The short way round through pi, not through 0.
  EXPECT_NEAR(std::abs(mid.theta), M_PI, 1e-12);
  EXPECT_DOUBLE_EQ(traj.at(-5.0).x, 0.0);
  EXPECT_DOUBLE_EQ(traj.at(9.0).y, 4.0);
  const Trajectory route =
      Trajectory::fromRoute({Vec2(0, 0), Vec2(10, 0), Vec2(10, 10)}, 2.0, 1.0, 2.0);
  EXPECT_DOUBLE_EQ(route.waypoints.front().t, 1.0);
  EXPECT_NEAR(route.at(3.0).x, 4.0, 1e-9);  // straight part at 2 m/s
  EXPECT_NEAR(route.waypoints.back().pose.theta, M_PI / 2, 1e-9);
}

TEST(GroundTruth, RasterisesAreasSurfacesAndDistances) {
  const GridWindow window = GridWindow::covering(Vec2(0, 0), Vec2(9.99, 9.99), 0.1);
  ASSERT_EQ(window.width, 100);
  const std::vector<Polygon> box = {makeRect(2.0, 3.0, 4.0, 4.0)};
  const std::vector<std::uint8_t> filled = rasteriseFilled(box, window);
  std::size_t count = 0;
  for (std::uint8_t v : filled) count += v;
  EXPECT_EQ(count, 20u * 10u);
  EXPECT_EQ(filled[window.index(25, 35)], 1);
  EXPECT_EQ(filled[window.index(19, 35)], 0);
  const std::vector<std::uint8_t> surface = rasteriseBoundary(box, window);
  EXPECT_EQ(surface[window.index(20, 35)], 1);
  EXPECT_EQ(surface[window.index(25, 35)], 0);

  // Exact Euclidean distance transform against brute force.
  std::vector<std::uint8_t> mask(window.size(), 0);
  mask[window.index(10, 10)] = 1;
  mask[window.index(70, 40)] = 1;
  mask[window.index(30, 90)] = 1;
  const std::vector<float> dist = distanceTransform(mask, window);
  for (int r = 0; r < window.height; r += 7) {
    for (int c = 0; c < window.width; c += 3) {
      double best = 1e9;
      for (auto [mc, mr] : {std::pair<int, int>{10, 10}, {70, 40}, {30, 90}}) {
        best = std::min(best, std::hypot(c - mc, r - mr) * 0.1);
      }
      EXPECT_NEAR(dist[window.index(c, r)], best, 1e-5);
    }
  }
}

TEST(WorldFile, RoundTripsTheDefaultWorld) {
  const World a = defaultWorld(30.0);
  const World b = parseWorld(worldToYaml(a), "default");
  ASSERT_EQ(a.objects.size(), b.objects.size());
  ASSERT_EQ(a.vehicle.lasers.size(), b.vehicle.lasers.size());
  EXPECT_EQ(a.duration, b.duration);
  for (double t : {0.0, 5.5, 12.0, 20.0, 28.0}) {
    const std::vector<Polygon> pa = a.polygonsAt(t);
    const std::vector<Polygon> pb = b.polygonsAt(t);
    ASSERT_EQ(pa.size(), pb.size()) << t;
    for (std::size_t i = 0; i < pa.size(); ++i) {
      for (std::size_t k = 0; k < pa[i].size(); ++k) {
        EXPECT_LT((pa[i][k] - pb[i][k]).norm(), 1e-9);
      }
    }
    const Pose2 va = a.vehicle.path.at(t);
    const Pose2 vb = b.vehicle.path.at(t);
    EXPECT_NEAR(va.x, vb.x, 1e-9);
    EXPECT_NEAR(va.theta, vb.theta, 1e-9);
  }
  for (std::size_t i = 0; i < a.vehicle.lasers.size(); ++i) {
    EXPECT_EQ(a.vehicle.lasers[i].topic, b.vehicle.lasers[i].topic);
    EXPECT_EQ(a.vehicle.lasers[i].frame_id, b.vehicle.lasers[i].frame_id);
    EXPECT_NEAR(a.vehicle.lasers[i].mount.theta, b.vehicle.lasers[i].mount.theta, 1e-12);
  }
}

TEST(WorldFile, ReadsJsonAndShortcuts) {
  const World w = parseWorld(R"({
    "name": "json_world", "duration": 2,
    "objects": [
      {"name": "w", "kind": "wall", "polygon": [[5, -1], [6, -1], [6, 1], [5, 1]]},
      {"name": "p", "kind": "pedestrian", "role": "moving", "circle": [0.3, 8],
       "route": {"speed": 1.0, "start": 0.5, "points": [[3, 3], [3, -3]]}}
    ],
    "vehicle": {"box": [8, 2.5], "trajectory": [[0, 0, 0, 0]],
                "lasers": [{"corner": "front_left"}, {"name": "top", "yaw_deg": 90, "beams": 181}]}
  })",
                             "inline json");
  EXPECT_EQ(w.name, "json_world");
  ASSERT_EQ(w.objects.size(), 2u);
  EXPECT_EQ(w.objects[1].kind, ObjectKind::kPedestrian);
  EXPECT_NEAR(w.objects[1].trajectory.at(1.5).y, 2.0, 1e-9);
  ASSERT_EQ(w.vehicle.lasers.size(), 2u);
  EXPECT_EQ(w.vehicle.lasers[0].topic, "scan_front_left");
  EXPECT_NEAR(w.vehicle.lasers[0].mount.x, 4.0, 1e-12);
  EXPECT_NEAR(w.vehicle.lasers[0].mount.theta, M_PI / 4, 1e-12);
  EXPECT_EQ(w.vehicle.lasers[1].frame_id, "laser_top");
  EXPECT_EQ(w.vehicle.lasers[1].beams, 181);
}

TEST(WorldFile, ErrorsNameTheEntry) {
  const std::string base = "vehicle: {trajectory: [[0, 0, 0, 0]], lasers: [{name: a}]}\n";
  auto message = [](const std::string& text) {
    try {
      parseWorld(text, "w.yaml");
    } catch (const WorldFileError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(base + "objects: [{kind: wall, box: [1, 1], colour: red}]")
                .find("objects[0]: unknown key 'colour'"),
            std::string::npos);
  EXPECT_NE(message(base + "objects: [{kind: tree, box: [1, 1]}]").find("objects[0].kind"),
            std::string::npos);
  EXPECT_NE(message(base + "duration: -1").find("duration must be > 0"), std::string::npos);
  EXPECT_NE(message("vehicle: [").find("w.yaml: syntax error"), std::string::npos);
  EXPECT_NO_THROW(parseWorld(base));
  EXPECT_THROW(loadWorld("/nonexistent/world.yaml"), WorldFileError);
}

TEST(DefaultWorld, HasNoCollisionsAndItsEventsAreSeen) {
  const World world = defaultWorld(60.0);
  EXPECT_TRUE(world.validate().empty());
  // The truck never drives through anything, and moving objects never overlap others.
  for (double t = 0.0; t < world.duration; t += 0.05) {
    const Polygon truck = transformed(world.vehicle.footprint, world.vehicle.path.at(t));
    for (const WorldObject& o : world.objects) {
      if (!o.presentAt(t)) continue;
      EXPECT_FALSE(polygonsIntersect(truck, o.polygonAt(t))) << o.name << " at t=" << t;
      if (o.role == ObjectRole::kStatic) continue;
      for (const WorldObject& other : world.objects) {
        if (&other == &o || !other.presentAt(t)) continue;
        EXPECT_FALSE(polygonsIntersect(o.polygonAt(t), other.polygonAt(t)))
            << o.name << " hits " << other.name << " at t=" << t;
      }
    }
  }
  // The departing and the arriving car are both hit by beams.
  int departing = -1, arriving = -1;
  for (std::size_t i = 0; i < world.objects.size(); ++i) {
    if (world.objects[i].role == ObjectRole::kDeparting) departing = static_cast<int>(i);
    if (world.objects[i].role == ObjectRole::kArriving) arriving = static_cast<int>(i);
  }
  ASSERT_GE(departing, 0);
  ASSERT_GE(arriving, 0);
  const ScanSimulator sim(world, kSeed);
  auto hits_on = [&sim](int object, double t0, double t1) {
    std::size_t hits = 0;
    for (int laser = 0; laser < 4; ++laser) {
      for (std::uint64_t seq = 0; sim.stampOf(laser, seq) < t1; seq += 8) {
        if (sim.stampOf(laser, seq) < t0) continue;
        for (int h : sim.simulate(laser, seq).hit_object) hits += h == object;
      }
    }
    return hits;
  };
  EXPECT_GT(hits_on(departing, 0.0, 10.0), 100u);  // seen parked
  EXPECT_GT(hits_on(arriving, 27.0, 40.0), 100u);  // seen after parking
}

}  // namespace
}  // namespace sim
}  // namespace wavog
