// The hierarchical tree must equal the dense cell-by-cell reference for every policy.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "dense_reference.h"
#include "test_support.h"

namespace wavog_test {
namespace {

using wavog::Aggregation;
using wavog::CellBox;
using wavog::MapParams;
using wavog::WaveletMap;

constexpr double kTolerance = 1e-4;  // |tree - ref| <= 1e-4 * max(1, |ref|), tau = 0

struct PolicyRun {
  std::vector<NamedParams> configs;
  std::vector<std::unique_ptr<WaveletMap>> maps;
  std::unique_ptr<DenseReference> ref;
  std::vector<std::size_t> integrated;  // per map: scans it integrated (status kOk)

  PolicyRun(std::vector<NamedParams> c, const CellBox& extent) : configs(std::move(c)) {
    std::vector<MapParams> layers;
    for (const auto& np : configs) {
      maps.push_back(std::make_unique<WaveletMap>(np.params));
      layers.push_back(np.params);
    }
    ref = std::make_unique<DenseReference>(layers, extent);
    integrated.assign(maps.size(), 0);
  }
  void integrate(const OwnedScan& s) {
    for (std::size_t i = 0; i < maps.size(); ++i) {
      if (maps[i]->integrate(s.pose, s.view()).status == wavog::ScanStatus::kOk) ++integrated[i];
    }
    ref->integrate(s.pose, s.view());
  }
  // Equal to the reference, and not vacuously: scans were integrated and cells observed (a
  // regression that refuses every scan, or changes nothing, fails here).
  void expectEqual(const std::string& when) {
    for (std::size_t i = 0; i < maps.size(); ++i) {
      EXPECT_GT(integrated[i], 0u) << configs[i].name << " " << when;
      EXPECT_GT(maps[i]->stats(true).observed_cells, 0u) << configs[i].name << " " << when;
      ref->selectLayer(i);
      const Comparison c = compare(*maps[i], *ref);
      EXPECT_LE(c.max_rel_error, kTolerance)
          << configs[i].name << " " << when << ": worst cell (" << c.worst_x << ", " << c.worst_y
          << ") tree " << maps[i]->value({c.worst_x, c.worst_y}) << " reference "
          << ref->value(c.worst_x, c.worst_y);
      EXPECT_EQ(c.knowledge_mismatches, 0u) << configs[i].name << " " << when;
    }
  }
  // Multiscale read-out: mean equals the reference block mean, max the block max over observed
  // cells, known iff any observed cell, for scales 0..max_scale over the whole extent.
  void expectMultiscale(int max_scale) {
    const CellBox& e = ref->extent();
    for (std::size_t i = 0; i < maps.size(); ++i) {
      ref->selectLayer(i);
      for (int s = 0; s <= max_scale; ++s) {
        // Scale-s cells lying wholly inside the reference's extent.
        const CellBox box{-((-e.min_x) >> s), -((-e.min_y) >> s), e.max_x >> s, e.max_y >> s};
        const auto mean = maps[i]->exportScale(s, box, Aggregation::kMean);
        const auto mx = maps[i]->exportScale(s, box, Aggregation::kMax);
        ASSERT_EQ(mean.log_odds.size(), static_cast<std::size_t>(box.width() * box.height()));
        double worst_mean = 0, worst_max = 0;
        std::size_t known_bad = 0;
        for (std::int64_t by = box.min_y; by < box.max_y; ++by) {
          for (std::int64_t bx = box.min_x; bx < box.max_x; ++bx) {
            const auto k =
                static_cast<std::size_t>((by - box.min_y) * box.width() + (bx - box.min_x));
            // A mean inherits the float round-off of the cells it averages: the tolerance is
            // relative to the largest of them (unbounded policies reach hundreds).
            const double want_mean = ref->blockMean(s, bx, by);
            double scale_of_block = std::fabs(want_mean);
            const std::int64_t size = std::int64_t{1} << s;
            for (std::int64_t y = by * size; y < (by + 1) * size; ++y)
              for (std::int64_t x = bx * size; x < (bx + 1) * size; ++x)
                scale_of_block = std::max(scale_of_block, std::fabs(ref->value(x, y)));
            worst_mean = std::max(worst_mean, std::fabs(mean.log_odds[k] - want_mean) /
                                                  std::max(1.0, scale_of_block));
            const bool any = ref->blockAnyKnown(s, bx, by);
            if ((mean.known[k] != 0) != any || (mx.known[k] != 0) != any) ++known_bad;
            if (any) {
              const double want_max = ref->blockMaxObserved(s, bx, by);
              worst_max = std::max(worst_max, std::fabs(mx.log_odds[k] - want_max) /
                                                  std::max(1.0, std::fabs(want_max)));
            }
          }
        }
        EXPECT_LE(worst_mean, kTolerance) << configs[i].name << " scale " << s << " mean";
        EXPECT_LE(worst_max, kTolerance) << configs[i].name << " scale " << s << " max";
        EXPECT_EQ(known_bad, 0u) << configs[i].name << " scale " << s << " knowledge";
      }
    }
  }
};

// (a) 300 seeded random scans from random poses with NaN, +-inf, zero and out-of-range beams.
TEST(ReferenceEquivalence, RandomScansEveryPolicy) {
  const double half = 12.0;  // poses in +-6 m, range_max 5.4 m
  for (int levels : {3, 5}) {
    const double res = 0.1;
    const auto cells = static_cast<std::int64_t>(std::ceil(half / res));
    PolicyRun run(everyPolicy(res, levels), CellBox{-cells, -cells, cells, cells});
    RandomScans scans(1234u + static_cast<std::uint32_t>(levels), half);
    for (int i = 1; i <= 300; ++i) {
      run.integrate(scans.next());
      if (i == 1 || i == 30 || i == 300)
        run.expectEqual("levels " + std::to_string(levels) + " after " + std::to_string(i) +
                        " scans");
    }
    run.expectMultiscale(std::min(levels, 4));
  }
}

// A sensor sitting exactly on cell corners and block corners, beams along the axes.
TEST(ReferenceEquivalence, DegenerateGeometry) {
  const double res = 0.1;
  PolicyRun run(everyPolicy(res, 4), CellBox{-64, -64, 64, 64});
  const double kPi = 3.14159265358979323846;
  for (int i = 0; i < 40; ++i) {
    OwnedScan s;
    s.pose = {(i % 2) ? 0.0 : 1.6, (i % 3) ? 0.0 : -1.6, (i % 4) * kPi / 2};
    s.angle_min = -kPi;
    s.angle_increment = kPi / 8;  // 16 beams over 2 pi: beams on the axes and diagonals
    s.range_min = 0.0;
    s.range_max = 5.0;
    for (int j = 0; j < 16; ++j)
      s.ranges.push_back(j % 5 == 0 ? std::numeric_limits<float>::infinity()
                                    : 1.6f + 0.8f * static_cast<float>(j % 3));
    run.integrate(s);
  }
  // Beam steps far below any cell's angular size (every bearing index overflows an integer).
  for (double inc : {1e-300, -1e-12}) {
    OwnedScan s;
    s.pose = {0.05, 0.05, 0.3};
    s.angle_min = 0.1;
    s.angle_increment = inc;
    s.range_min = 0.0;
    s.range_max = 5.0;
    s.ranges = {2.0f, 2.5f, std::numeric_limits<float>::infinity()};
    run.integrate(s);
  }
  run.expectEqual("degenerate");
  run.expectMultiscale(4);
}

// Many beams whose sector boundaries run exactly through cell centres and corners (sensor on a
// cell centre or corner, boundaries on the axes and diagonals), with neighbouring sectors that
// disagree: the boundary-ray tests must hand those cells to the same sector as the reference.
TEST(ReferenceEquivalence, SectorBoundariesThroughCellCentres) {
  const double res = 0.1;
  PolicyRun run(everyPolicy(res, 5), CellBox{-96, -96, 96, 96});
  const double kPi = 3.14159265358979323846;
  const int beams = 128;
  const double inc = 2 * kPi / beams;
  for (int i = 0; i < 24; ++i) {
    OwnedScan s;
    const double off = (i % 2) ? 0.5 * res : 0.0;  // cell centre or cell corner
    s.pose = {off + res * static_cast<double>(i % 5 - 2), off - res * static_cast<double>(i % 3),
              (i % 8) * kPi / 4};
    s.angle_min = -kPi + 0.5 * inc;  // boundaries at multiples of inc, axes and diagonals included
    s.angle_increment = (i % 3 == 2) ? -inc : inc;
    if (s.angle_increment < 0) s.angle_min = kPi - 0.5 * inc;
    s.range_min = 0.0;
    s.range_max = 8.0;
    for (int j = 0; j < beams; ++j) {
      float r = (j + i) % 2 ? 0.65f : 3.05f + 0.1f * static_cast<float>(j % 4);
      if (j % 29 == 3) r = std::numeric_limits<float>::quiet_NaN();
      if (j % 31 == 7) r = std::numeric_limits<float>::infinity();
      s.ranges.push_back(r);
    }
    run.integrate(s);
  }
  run.expectEqual("boundaries through cell centres");
}

// (b) The first 500 scans of the Freiburg fr079 log.
TEST(ReferenceEquivalence, RealDataFr079First500Scans) {
  const std::vector<OwnedScan> log = fr079Scans(500);
  ASSERT_EQ(log.size(), 500u);
  const double res = 0.1;
  // Extent: every endpoint and pose, with a margin.
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  for (const OwnedScan& s : log) {
    for (std::size_t j = 0; j < s.ranges.size(); ++j) {
      const double z = s.ranges[j];
      if (!std::isfinite(z) || z >= s.range_max) continue;
      const double b = s.pose.theta + s.angle_min + static_cast<double>(j) * s.angle_increment;
      x0 = std::min(x0, s.pose.x + z * std::cos(b));
      x1 = std::max(x1, s.pose.x + z * std::cos(b));
      y0 = std::min(y0, s.pose.y + z * std::sin(b));
      y1 = std::max(y1, s.pose.y + z * std::sin(b));
    }
  }
  const CellBox extent{static_cast<std::int64_t>(std::floor(x0 / res)) - 4,
                       static_cast<std::int64_t>(std::floor(y0 / res)) - 4,
                       static_cast<std::int64_t>(std::floor(x1 / res)) + 5,
                       static_cast<std::int64_t>(std::floor(y1 / res)) + 5};
  PolicyRun run(everyPolicy(res, 6), extent);
  for (const OwnedScan& s : log) run.integrate(s);
  run.expectEqual("fr079 500 scans");
  run.expectMultiscale(4);
}

}  // namespace
}  // namespace wavog_test
