// NDT cells against the simulator's true walls (wall_metrics.h ndtWallDistance, and the figure
// wavog_evaluate --ndt reports): the metric on hand-made cells and Gaussians beside a known wall,
// then the car park through the core under three policies, where the NDT means must lie nearer
// to the walls than the occupied cells' centres, and within half a cell (paper section 1.2.3).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "wavog_mapping/sim/evaluation.h"
#include "wavog_mapping/sim/laser_sim.h"
#include "wavog_mapping/sim/wall_metrics.h"
#include "wavog_mapping/sim/world.h"

namespace wavog {
namespace sim {
namespace {

constexpr double kResolution = 0.1;

// One wall whose free face is the line x = 1.03 (not on a cell boundary), from y = -5 to 5.
World oneWall() {
  World w;
  w.name = "one_wall";
  WorldObject o;
  o.name = "wall";
  o.kind = ObjectKind::kWall;
  o.shape = makeRect(1.03, -5.0, 1.5, 5.0);
  w.objects.push_back(o);
  return w;
}

NdtCell gaussianAt(std::int64_t ix, std::int64_t iy, double x, double y, float log_odds) {
  NdtCell c;
  c.ix = ix;
  c.iy = iy;
  c.weight = 5.0;
  c.mean_x = x;
  c.mean_y = y;
  c.cov_yy = 0.001;
  c.log_odds = log_odds;
  return c;
}

TEST(NdtWallDistance, CellCentresAndMeansOfHandMadeCellsBesideAKnownWall) {
  const World world = oneWall();
  // 20 x 20 cells of 0.1 m over [0, 2) x [-1, 1); the cells of column 10 (x in [1.0, 1.1),
  // centres 0.02 m behind the face) occupied, and one occupied cell 0.98 m from the wall, beyond
  // the margin of 0.5 m.
  Raster map;
  map.cell_size = kResolution;
  map.box = CellBox{0, -10, 20, 10};
  map.log_odds.assign(400, -1.0f);
  map.known.assign(400, 1);
  for (int row = 0; row < 20; ++row) map.log_odds[static_cast<std::size_t>(row * 20 + 10)] = 2.0f;
  map.log_odds[5 * 20 + 0] = 2.0f;
  NdtLayer ndt;
  ndt.cell_size = kResolution;
  ndt.box = map.box;
  // Means 5 mm either side of the face in six of the occupied wall cells.
  for (int iy = -3; iy < 3; ++iy) {
    ndt.cells.push_back(gaussianAt(10, iy, iy % 2 ? 1.025 : 1.035, 0.1 * iy + 0.05, 2.0f));
  }
  ndt.cells.push_back(gaussianAt(9, 0, 0.99, 0.05, -1.0f));   // a free cell: not counted
  ndt.cells.push_back(gaussianAt(0, -5, 0.05, -0.45, 2.0f));  // beyond the margin
  ndt.cells.push_back(gaussianAt(40, 0, 4.05, 0.05, 2.0f));   // outside the raster

  const NdtWallDistance d = ndtWallDistance(world, 0.0, map, ndt, 0.5);
  EXPECT_EQ(d.cells, 20u);
  EXPECT_NEAR(d.cell_centre_m, 0.02, 1e-9);
  EXPECT_EQ(d.gaussians, 6u);
  EXPECT_NEAR(d.ndt_cell_centre_m, 0.02, 1e-9);
  EXPECT_NEAR(d.ndt_mean_m, 0.005, 1e-9);

  // Nothing occupied, nothing to average: NaN. Gaussians of another cell size are refused.
  Raster free_map = map;
  free_map.log_odds.assign(400, -1.0f);
  const NdtWallDistance none = ndtWallDistance(world, 0.0, free_map, ndt, 0.5);
  EXPECT_EQ(none.cells, 0u);
  EXPECT_TRUE(std::isnan(none.cell_centre_m));
  EXPECT_EQ(none.gaussians, 0u);
  EXPECT_TRUE(std::isnan(none.ndt_mean_m));
  ndt.cell_size = 0.2;
  EXPECT_THROW(ndtWallDistance(world, 0.0, map, ndt, 0.5), std::invalid_argument);
}

TEST(NdtWallDistance, ExactDistanceToTheNearestWallEdge) {
  const World world = oneWall();
  EXPECT_NEAR(distanceToWallEdges(world, 0.0, Vec2(0.0, 0.0)), 1.03, 1e-12);
  EXPECT_NEAR(distanceToWallEdges(world, 0.0, Vec2(1.2, 0.0)), 0.17, 1e-12);  // inside the wall
  EXPECT_NEAR(distanceToWallEdges(world, 0.0, Vec2(1.03, 7.0)), 2.0, 1e-12);  // past its end
  EXPECT_TRUE(std::isinf(distanceToWallEdges(World{}, 0.0, Vec2(0.0, 0.0))));
}

// The car park's first 20 s (the truck passes walls and pillars) under three policies.
TEST(NdtWallDistance, NdtMeansLieNearerToTheCarParkWallsThanCellCentres) {
  const World world = defaultWorld(20.0);
  const std::vector<SimScan> scans = simulateAll(world, 1);
  const std::vector<WorldEvent> events;  // the responses are not asked for here
  for (const PolicyRun& run : standardPolicies(kResolution)) {
    if (run.params.policy.init != InitValue::kUnknown) continue;
    const PolicyType type = run.params.policy.type;
    if (type != PolicyType::kNone && type != PolicyType::kMax && type != PolicyType::kForget) {
      continue;
    }
    PolicyRun with_ndt = run;
    with_ndt.params.ndt = true;
    const PolicyResult r = evaluatePolicy(world, scans, events, with_ndt);
    const NdtWallDistance& d = r.ndt_walls;
    SCOPED_TRACE(r.label);
    std::cout << r.label << ": " << d.cells << " occupied cells near walls, centres "
              << 100 * d.cell_centre_m << " cm; " << d.gaussians << " with a Gaussian, centres "
              << 100 * d.ndt_cell_centre_m << " cm, NDT means " << 100 * d.ndt_mean_m << " cm\n";
    ASSERT_GT(d.cells, 500u);
    ASSERT_GT(d.gaussians, d.cells / 4);
    EXPECT_LE(d.gaussians, d.cells);
    EXPECT_GE(r.ndt_cells, d.gaussians);
    ASSERT_TRUE(std::isfinite(d.cell_centre_m));
    ASSERT_TRUE(std::isfinite(d.ndt_cell_centre_m));
    ASSERT_TRUE(std::isfinite(d.ndt_mean_m));
    // The walls lie on cell boundaries: a centre is at least half a cell from its wall.
    EXPECT_GE(d.ndt_cell_centre_m, 0.5 * kResolution - 1e-9);
    EXPECT_LT(d.ndt_mean_m, d.cell_centre_m);
    EXPECT_LT(d.ndt_mean_m, d.ndt_cell_centre_m);
    EXPECT_LT(d.ndt_mean_m, 0.5 * kResolution);
  }
}

}  // namespace
}  // namespace sim
}  // namespace wavog
