// Policies on a short simulated scenario (one laser facing a wall, a parked car in between that
// vanishes): how many scans the departed car's cells take to become free again. The expected
// counts come from the closed forms (ALGORITHM.md eq. 1.7 for forgetting, additive steps for
// clamping) applied to the values the map actually holds at the departure, never from constants.
#include <gtest/gtest.h>

#include <cmath>

#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/sim/evaluation.h"
#include "wavog_mapping/sim/laser_sim.h"
#include "wavog_mapping/sim/world.h"

namespace wavog {
namespace sim {
namespace {

constexpr double kDepart = 2.0;    // s: 80 scans of the parked car at 40 Hz
constexpr double kDuration = 6.0;  // s: 160 scans after it left
constexpr double kResolution = 0.1;
constexpr std::uint64_t kSeed = 7;

struct CellTrace {
  CellIndex cell;
  float at_departure = 0.0f;  // value after the last scan that saw the car
  int scans_to_free = -1;     // scans after the departure until value < 0; -1: never
};

class PolicyResponse : public ::testing::Test {
 protected:
  void SetUp() override {
    world_ = testWorld(kDepart, kDuration, /*noise_sigma=*/0.01);
    scans_ = simulateAll(world_, kSeed);
    events_ = findEvents(world_, scans_, kResolution);
    ASSERT_EQ(events_.size(), 1u);
    ASSERT_GE(events_[0].cells.size(), 10u) << "the car's front must be seen by several cells";
  }

  MapParams params(PolicyType type) const {
    MapParams p = MapParams::defaultsFor(type);
    p.grid.resolution = kResolution;
    return p;
  }

  // Runs every scan and follows each of the car's cells.
  std::vector<CellTrace> trace(const MapParams& p) const {
    WaveletMap map(p);
    std::vector<CellTrace> traces;
    for (const CellIndex& c : events_[0].cells) traces.push_back(CellTrace{c, 0.0f, -1});
    int after = 0;
    for (const SimScan& s : scans_) {
      map.integrate(s.sensor_pose, s.view(world_.vehicle.lasers[0]));
      if (s.stamp < kDepart) {
        for (CellTrace& t : traces) t.at_departure = map.value(t.cell);
        continue;
      }
      ++after;
      for (CellTrace& t : traces) {
        if (t.scans_to_free < 0 && map.value(t.cell) < 0.0f) t.scans_to_free = after;
      }
    }
    return traces;
  }

  World world_;
  std::vector<SimScan> scans_;
  std::vector<WorldEvent> events_;
};

TEST_F(PolicyResponse, ForgettingFreesTheCarWithinTheClosedFormCount) {
  const MapParams p = params(PolicyType::kForget);
  const std::vector<CellTrace> traces = trace(p);
  int occupied = 0;
  int exact = 0;
  for (const CellTrace& t : traces) {
    // Forgetting blends hits and misses: a corner cell hit by few beams may already be free.
    if (t.at_departure <= 0.0f) continue;
    ++occupied;
    const int predicted = forgettingScansToFree(t.at_departure, p.policy.gamma, p.sensor.odd_emp);
    ASSERT_GT(predicted, 0);
    EXPECT_GE(t.scans_to_free, 1) << "cell (" << t.cell.x << ", " << t.cell.y << ")";
    EXPECT_LE(t.scans_to_free, predicted) << "cell (" << t.cell.x << ", " << t.cell.y << ")";
    exact += t.scans_to_free == predicted;
  }
  EXPECT_GE(occupied, static_cast<int>(traces.size() * 8 / 10));
  // Cells seen empty by every scan after the departure take exactly the predicted count.
  EXPECT_GE(exact, occupied / 2);
}

TEST_F(PolicyResponse, MaxNeverFreesTheCar) {
  for (const CellTrace& t : trace(params(PolicyType::kMax))) {
    EXPECT_GT(t.at_departure, 0.0f);
    EXPECT_EQ(t.scans_to_free, -1) << "cell (" << t.cell.x << ", " << t.cell.y << ")";
  }
}

TEST_F(PolicyResponse, ClampingFreesTheCarOnlyAfterWorkingDownFromTheBound) {
  const MapParams p = params(PolicyType::kClamp);
  const std::vector<CellTrace> traces = trace(p);
  int saturated = 0;
  for (const CellTrace& t : traces) {
    // Never above the bound; and a cell at the bound needs the bound's worth of empty scans.
    EXPECT_LE(t.at_departure, p.policy.clamp_max + 1e-5);
    saturated += std::abs(t.at_departure - p.policy.clamp_max) < 1e-4;
    const int predicted = additiveScansToFree(t.at_departure, p.sensor.odd_emp);
    EXPECT_EQ(t.scans_to_free, predicted) << "cell (" << t.cell.x << ", " << t.cell.y << ")";
  }
  EXPECT_GT(saturated, 0) << "80 scans of hits must reach the upper bound";
  // Without the bound the same cells stay occupied far longer (overconfidence).
  const std::vector<CellTrace> none = trace(params(PolicyType::kNone));
  for (std::size_t i = 0; i < traces.size(); ++i) {
    if (std::abs(traces[i].at_departure - p.policy.clamp_max) > 1e-4) continue;
    EXPECT_GT(none[i].at_departure, p.policy.clamp_max);
    EXPECT_TRUE(none[i].scans_to_free < 0 || none[i].scans_to_free > traces[i].scans_to_free);
  }
}

TEST_F(PolicyResponse, EvaluationReportsTheSameOrdering) {
  std::map<std::string, PolicyResult> by_label;
  for (const PolicyRun& run : standardPolicies(kResolution)) {
    by_label[run.label] = evaluatePolicy(world_, scans_, events_, run);
  }
  const EventResponse& forget = by_label.at("forget / unknown").events[0];
  const EventResponse& clamp = by_label.at("clamp / unknown").events[0];
  const EventResponse& max = by_label.at("max / unknown").events[0];
  ASSERT_TRUE(forget.reached());
  ASSERT_TRUE(clamp.reached());
  EXPECT_FALSE(max.reached());
  EXPECT_LT(forget.scans, clamp.scans);
  EXPECT_NEAR(forget.seconds, (forget.scans - 1) / 40.0, 1e-6);
  // The wall is seen, and the final maps' occupied cells lie on it (the car is gone).
  const PolicyResult& f = by_label.at("forget / unknown");
  EXPECT_GT(f.precision, 0.9);
  EXPECT_GT(f.recall, 0.9);
  EXPECT_LT(f.wall_distance, 2 * kResolution);
  EXPECT_LT(by_label.at("max / unknown").precision, f.precision);
}

TEST(ClosedForms, MatchIteratingTheUpdates) {
  for (double x0 : {0.5, 3.5, 10.1}) {
    double x = x0;
    int n = 0;
    while (x >= 0.0) {
      x = 0.7 * x + 0.3 * -2.0;
      ++n;
    }
    EXPECT_EQ(forgettingScansToFree(x0, 0.3, -2.0), n) << x0;
    x = x0;
    n = 0;
    while (x >= 0.0) {
      x += -0.4;
      ++n;
    }
    EXPECT_EQ(additiveScansToFree(x0, -0.4), n) << x0;
  }
  EXPECT_EQ(forgettingScansToFree(-1.0, 0.3, -2.0), 0);
}

}  // namespace
}  // namespace sim
}  // namespace wavog
