// One scan integrated very many times (a vehicle parked for hours, issue 37): under every policy
// the cells the scan does not see keep their values and stay unobserved, and the map still equals
// the dense reference. Under the unbounded policies the observed cells' log-odds grow with every
// repetition; the float Haar details must still reconstruct their neighbours.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "dense_reference.h"
#include "test_support.h"

namespace wavog_test {
namespace {

using wavog::CellBox;
using wavog::CellClass;
using wavog::MapParams;
using wavog::WaveletMap;

constexpr double kTolerance = 1e-4;  // as test_reference_equivalence: * max(1, |reference|)
constexpr std::size_t kRepetitions = 100000;

OwnedScan fan(double x, double y, double theta, double angle_min, double increment,
              std::vector<float> ranges) {
  OwnedScan s;
  s.pose = {x, y, theta};
  s.angle_min = angle_min;
  s.angle_increment = increment;
  s.range_min = 0.0;
  s.range_max = 4.0;
  s.ranges = std::move(ranges);
  return s;
}

TEST(RepeatedScan, CellsOutsideTheScanKeepTheirValuesEveryPolicy) {
  const double res = 0.1;
  const int levels = 9;                  // the default: the deepest tree of the usual maps
  const CellBox extent{0, 0, 512, 512};  // the one block every scan below lies in
  const std::vector<NamedParams> configs = everyPolicy(res, levels);
  std::vector<MapParams> layers;
  std::vector<std::unique_ptr<WaveletMap>> maps;
  for (const auto& c : configs) {
    layers.push_back(c.params);
    maps.push_back(std::make_unique<WaveletMap>(c.params));
  }
  DenseReference ref(layers, extent);

  // Cells observed before: a fan up from the parking pose (beside the repeated fan, sharing its
  // apex), and a ring elsewhere in the block (so that coarse details hold other cells).
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<OwnedScan> before = {
      fan(20.02, 20.03, 1.5708, -0.5, 0.1, {0.8f, 0.9f, 1.0f, inf, 1.1f, 1.2f, 0.9f, 0.8f, 1.0f,
                                           1.1f, 0.9f}),
      fan(5.0, 5.0, 0.0, -3.1, 0.1, std::vector<float>(62, 2.0f)),
  };
  // The repeated scan: a small fan to +x from the same pose.
  const OwnedScan parked =
      fan(20.02, 20.03, 0.0, -0.4, 0.1, {0.8f, 0.8f, 0.9f, 0.8f, 0.7f, 0.8f, 0.9f, 0.8f, 0.8f});

  for (const OwnedScan& s : before) {
    for (auto& m : maps) ASSERT_EQ(m->integrate(s.pose, s.view()).status, wavog::ScanStatus::kOk);
    ref.integrate(s.pose, s.view());
  }
  // The cells the repeated scan leaves U, with their values and knowledge before it.
  ReferenceClassifier cls;
  ASSERT_TRUE(cls.prepare(configs[0].params, parked.pose, parked.view()));
  struct Cell {
    std::int64_t x, y;
  };
  std::vector<Cell> outside;
  std::size_t observed_outside = 0, seen = 0;
  for (std::int64_t y = extent.min_y; y < extent.max_y; ++y) {
    for (std::int64_t x = extent.min_x; x < extent.max_x; ++x) {
      if (cls.cellClass(x, y) != CellClass::kUnknown) {
        ++seen;
        continue;
      }
      outside.push_back({x, y});
      if (ref.known(x, y)) ++observed_outside;
    }
  }
  ASSERT_GT(seen, 20u);
  ASSERT_GT(observed_outside, 100u);  // observed cells beside the fan, and unobserved ones
  std::vector<std::vector<float>> value_before(maps.size());
  std::vector<std::vector<bool>> known_before(maps.size());
  for (std::size_t i = 0; i < maps.size(); ++i) {
    for (const Cell& c : outside) {
      value_before[i].push_back(maps[i]->value({c.x, c.y}));
      known_before[i].push_back(maps[i]->isObserved({c.x, c.y}));
    }
  }

  for (std::size_t i = 0; i < maps.size(); ++i) {
    for (std::size_t r = 0; r < kRepetitions; ++r) {
      ASSERT_EQ(maps[i]->integrate(parked.pose, parked.view()).status, wavog::ScanStatus::kOk);
    }
  }
  ref.integrate(parked.pose, parked.view(), kRepetitions);

  for (std::size_t i = 0; i < maps.size(); ++i) {
    const std::string& name = configs[i].name;
    double worst = 0;
    std::size_t worst_k = 0, knowledge_changed = 0;
    for (std::size_t k = 0; k < outside.size(); ++k) {
      const double was = value_before[i][k];
      const double now = maps[i]->value({outside[k].x, outside[k].y});
      const double err = std::fabs(now - was) / std::max(1.0, std::fabs(was));
      if (err > worst) {
        worst = err;
        worst_k = k;
      }
      if (maps[i]->isObserved({outside[k].x, outside[k].y}) != known_before[i][k])
        ++knowledge_changed;
    }
    EXPECT_LE(worst, kTolerance) << name << ": cell (" << outside[worst_k].x << ", "
                                 << outside[worst_k].y << ") outside the scan was "
                                 << value_before[i][worst_k] << ", is "
                                 << maps[i]->value({outside[worst_k].x, outside[worst_k].y});
    EXPECT_EQ(knowledge_changed, 0u) << name;
    ref.selectLayer(i);
    const Comparison c = compare(*maps[i], ref);
    EXPECT_LE(c.max_rel_error, kTolerance)
        << name << ": worst cell (" << c.worst_x << ", " << c.worst_y << ") tree "
        << maps[i]->value({c.worst_x, c.worst_y}) << " reference "
        << ref.value(c.worst_x, c.worst_y);
    EXPECT_EQ(c.knowledge_mismatches, 0u) << name;
  }
}

}  // namespace
}  // namespace wavog_test
