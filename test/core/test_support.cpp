#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <utility>

#include "wavog_mapping/io/carmen_reader.h"

namespace wavog_test {

using wavog::InitValue;
using wavog::MapParams;
using wavog::PolicyType;

std::vector<NamedParams> everyPolicy(double resolution, int block_levels) {
  std::vector<NamedParams> out;
  const auto add = [&](const std::string& name, PolicyType t, InitValue init) {
    MapParams p = MapParams::defaultsFor(t);
    p.grid.resolution = resolution;
    p.grid.block_levels = block_levels;
    p.policy.init = init;
    out.push_back({name, p});
  };
  add("none", PolicyType::kNone, InitValue::kUnknown);
  add("max", PolicyType::kMax, InitValue::kUnknown);
  add("max_empty_init", PolicyType::kMax, InitValue::kEmptyBound);
  add("clamp", PolicyType::kClamp, InitValue::kUnknown);
  add("clamp_empty_init", PolicyType::kClamp, InitValue::kEmptyBound);
  add("forget", PolicyType::kForget, InitValue::kUnknown);
  add("forget_empty_init", PolicyType::kForget, InitValue::kEmptyBound);
  add("clamp_lower", PolicyType::kClampLower, InitValue::kUnknown);
  add("clamp_upper", PolicyType::kClampUpper, InitValue::kUnknown);
  return out;
}

std::vector<NamedParams> everyPolicyWithVariants(double resolution, int block_levels,
                                                 const std::vector<std::string>& payload_policies) {
  auto out = everyPolicy(resolution, block_levels);
  for (const auto& base : everyPolicy(resolution, block_levels)) {
    if (base.name != "forget") continue;
    NamedParams eager = base;
    eager.name = "forget_eager";
    eager.params.lazy_forgetting = false;
    out.push_back(eager);
    NamedParams pruned = base;
    pruned.name = "forget_pruned_skip";
    pruned.params.prune_threshold = 0.05;
    pruned.params.skip_tolerance = 0.01;
    out.push_back(pruned);
  }
  for (const auto& base : everyPolicy(resolution, block_levels)) {
    if (std::find(payload_policies.begin(), payload_policies.end(), base.name) ==
        payload_policies.end()) {
      continue;
    }
    NamedParams payloads = base;
    payloads.name = base.name + "_reflection_ndt";
    payloads.params.reflection = true;
    payloads.params.ndt = true;
    if (base.name == "forget") payloads.params.policy.forget_half_life = 0.2;
    out.push_back(payloads);
  }
  return out;
}

std::vector<PolicyType> everyPolicyType() {
  return {PolicyType::kNone,   PolicyType::kMax,        PolicyType::kClamp,
          PolicyType::kForget, PolicyType::kClampLower, PolicyType::kClampUpper};
}

void expectSameCells(const wavog::WaveletMap& a, const wavog::WaveletMap& b, int half,
                     double tolerance) {
  for (std::int64_t iy = -half; iy < half; ++iy) {
    for (std::int64_t ix = -half; ix < half; ++ix) {
      const wavog::CellIndex c{ix, iy};
      ASSERT_EQ(a.isObserved(c), b.isObserved(c)) << ix << ", " << iy;
      ASSERT_NEAR(a.value(c), b.value(c), tolerance * std::max(1.0, std::fabs(double{b.value(c)})))
          << ix << ", " << iy;
    }
  }
}

wavog::ScanView OwnedScan::view() const {
  return wavog::ScanView{ranges.data(),   ranges.size(), angle_min,
                         angle_increment, range_min,     range_max};
}

OwnedScan RandomScans::next() {
  const double kPi = 3.14159265358979323846;
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  OwnedScan s;
  s.pose = {(u01(rng_) - 0.5) * half_, (u01(rng_) - 0.5) * half_, (u01(rng_) - 0.5) * 2 * kPi};
  const int n = 8 + static_cast<int>(u01(rng_) * 180);
  const double fov = u01(rng_) < 0.15 ? 2 * kPi : (0.2 + u01(rng_) * 1.6) * kPi;
  s.angle_increment = fov / n * (u01(rng_) < 0.3 ? -1.0 : 1.0);
  s.angle_min = (u01(rng_) - 0.5) * 2 * kPi;
  s.range_min = 0.05;
  s.range_max = 0.45 * half_;
  const float inf = std::numeric_limits<float>::infinity();
  s.ranges.resize(static_cast<std::size_t>(n));
  // Smooth-ish ranges (walls) with random defects.
  double r = s.range_max * (0.2 + 0.6 * u01(rng_));
  for (auto& z : s.ranges) {
    r = std::clamp(r + (u01(rng_) - 0.5) * 0.1 * s.range_max, 0.1, 0.95 * s.range_max);
    const double pick = u01(rng_);
    if (pick < 0.04)
      z = std::numeric_limits<float>::quiet_NaN();
    else if (pick < 0.08)
      z = inf;
    else if (pick < 0.10)
      z = -inf;
    else if (pick < 0.12)
      z = 0.0f;
    else if (pick < 0.14)
      z = static_cast<float>(0.5 * s.range_min);
    else if (pick < 0.17)
      z = static_cast<float>(s.range_max * (1.0 + u01(rng_)));
    else
      z = static_cast<float>(r);
  }
  return s;
}

Comparison compare(const wavog::WaveletMap& map, const DenseReference& ref) {
  Comparison c;
  const auto& e = ref.extent();
  for (std::int64_t y = e.min_y; y < e.max_y; ++y) {
    for (std::int64_t x = e.min_x; x < e.max_x; ++x) {
      const double want = ref.value(x, y);
      const double got = map.value({x, y});
      const double err = std::fabs(got - want) / std::max(1.0, std::fabs(want));
      if (err > c.max_rel_error) {
        c.max_rel_error = err;
        c.worst_x = x;
        c.worst_y = y;
      }
      if (map.isObserved({x, y}) != ref.known(x, y)) ++c.knowledge_mismatches;
    }
  }
  return c;
}

std::vector<OwnedScan> fr079Scans(std::size_t n) {
  std::vector<OwnedScan> out;
  const std::string dir = dataDir();
  if (dir.empty()) return out;
  for (const auto& s : wavog::readCarmenLog(dir + "/fr079-corrected.log.gz", n)) {
    OwnedScan o;
    o.pose = s.laser_pose;
    const auto v = s.view();
    o.ranges.assign(v.ranges, v.ranges + v.count);
    o.angle_min = v.angle_min;
    o.angle_increment = v.angle_increment;
    o.range_min = v.range_min;
    o.range_max = v.range_max;
    out.push_back(std::move(o));
  }
  return out;
}

std::string dataDir() {
  if (const char* env = std::getenv("WAVOG_DATA_DIR")) return env;
  const std::string candidates[] = {std::string(WAVOG_SOURCE_DIR) + "/../shared/data",
                                    "../shared/data", "../../shared/data"};
  for (const auto& dir : candidates) {
    if (std::ifstream(dir + "/fr079-corrected.log.gz").good()) return dir;
  }
  ADD_FAILURE() << "shared data not found: set WAVOG_DATA_DIR or put ../shared/data beside the "
                   "repository";
  return "";
}

}  // namespace wavog_test
