// One failing case per validate() rule; an invalid map cannot be built.
#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <stdexcept>

#include "wavog_mapping/core/limits.h"
#include "wavog_mapping/core/params.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace {

using wavog::MapParams;

struct Rule {
  const char* param;
  std::function<void(MapParams*)> breakIt;
};

TEST(Params, DefaultsAreValidForEveryPolicy) {
  EXPECT_TRUE(MapParams{}.validate().empty());
  for (auto t : {wavog::PolicyType::kNone, wavog::PolicyType::kMax, wavog::PolicyType::kClamp,
                 wavog::PolicyType::kForget, wavog::PolicyType::kClampLower,
                 wavog::PolicyType::kClampUpper}) {
    EXPECT_TRUE(MapParams::defaultsFor(t).validate().empty()) << wavog::toString(t);
  }
  EXPECT_EQ(MapParams::defaultsFor(wavog::PolicyType::kForget).sensor.odd_emp, -2.0);
  EXPECT_EQ(MapParams::defaultsFor(wavog::PolicyType::kClamp).sensor.odd_occ, 0.85);
}

TEST(Params, EachRuleNamesItsParameter) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Rule> rules = {
      {"resolution", [](MapParams* p) { p->grid.resolution = 0.0; }},
      {"resolution", [nan](MapParams* p) { p->grid.resolution = nan; }},
      {"block_levels", [](MapParams* p) { p->grid.block_levels = 1; }},
      {"block_levels", [](MapParams* p) { p->grid.block_levels = 13; }},
      {"odd_occ", [](MapParams* p) { p->sensor.odd_occ = -0.1; }},
      {"odd_emp", [](MapParams* p) { p->sensor.odd_emp = 0.2; }},
      {"band_width", [](MapParams* p) { p->sensor.band_width = -1; }},
      {"max_range", [](MapParams* p) { p->sensor.max_range = -1; }},
      {"no_return_clear", [](MapParams* p) { p->sensor.no_return_clear = -2; }},
      {"gamma", [](MapParams* p) { p->policy.gamma = 0.0; }},
      {"gamma", [](MapParams* p) { p->policy.gamma = 1.5; }},
      {"clamp_min", [](MapParams* p) { p->policy.clamp_min = 0.5; }},
      {"clamp_max", [](MapParams* p) { p->policy.clamp_max = -0.5; }},
      {"prune_threshold", [](MapParams* p) { p->prune_threshold = -0.01; }},
      {"skip_tolerance", [](MapParams* p) { p->skip_tolerance = 2.0; }},
  };
  for (const auto& rule : rules) {
    MapParams p;
    rule.breakIt(&p);
    const auto errors = p.validate();
    ASSERT_EQ(errors.size(), 1u) << rule.param;
    EXPECT_NE(errors[0].find(rule.param), std::string::npos) << errors[0];
    EXPECT_THROW(wavog::WaveletMap{p}, std::invalid_argument) << rule.param;
  }
}

// Issue 42, item 4: a band of more than kMaxBandCells cells is refused, naming band_width and
// resolution (its cells are walked one by one); at the limit it is accepted.
TEST(Params, BandWiderThanItsCellLimitIsRefused) {
  for (const double res : {1.01e-3, 0.01, 0.0195}) {
    MapParams p;
    p.grid.resolution = res;
    p.sensor.band_width = 10.0;  // the largest band_width allowed at any resolution
    const auto errors = p.validate();
    ASSERT_EQ(errors.size(), 1u) << res;
    EXPECT_NE(errors[0].find("band_width"), std::string::npos) << errors[0];
    EXPECT_NE(errors[0].find("resolution"), std::string::npos) << errors[0];
    EXPECT_THROW(wavog::WaveletMap{p}, std::invalid_argument) << res;
    p.sensor.band_width = 0.999 * wavog::kMaxBandCells * res;
    EXPECT_TRUE(p.validate().empty()) << res;
  }
  MapParams coarse;
  coarse.grid.resolution = 0.02;  // 500 cells of band
  coarse.sensor.band_width = 10.0;
  EXPECT_TRUE(coarse.validate().empty());
}

TEST(Params, EveryViolationIsListed) {
  MapParams p;
  p.grid.resolution = -1;
  p.policy.gamma = 3;
  p.sensor.odd_emp = 1;
  EXPECT_EQ(p.validate().size(), 3u);
  try {
    wavog::WaveletMap m(p);
    FAIL() << "built an invalid map";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("resolution"), std::string::npos);
    EXPECT_NE(what.find("gamma"), std::string::npos);
    EXPECT_NE(what.find("odd_emp"), std::string::npos);
  }
}

TEST(Params, NamesRoundTrip) {
  for (auto t : {wavog::PolicyType::kNone, wavog::PolicyType::kMax, wavog::PolicyType::kClamp,
                 wavog::PolicyType::kForget, wavog::PolicyType::kClampLower,
                 wavog::PolicyType::kClampUpper}) {
    wavog::PolicyType back;
    ASSERT_TRUE(wavog::fromString(wavog::toString(t), &back));
    EXPECT_EQ(back, t);
  }
  wavog::PolicyType t;
  EXPECT_FALSE(wavog::fromString("forgetting", &t));
  wavog::InitValue i;
  EXPECT_TRUE(wavog::fromString("empty_bound", &i));
  EXPECT_EQ(i, wavog::InitValue::kEmptyBound);
  EXPECT_FALSE(wavog::fromString("empty", &i));
}

TEST(Params, InitValueFollowsPolicy) {
  MapParams p = MapParams::defaultsFor(wavog::PolicyType::kClamp);
  EXPECT_EQ(p.initValue(), 0.0);
  p.policy.init = wavog::InitValue::kEmptyBound;
  EXPECT_EQ(p.initValue(), p.policy.clamp_min);
  MapParams f = MapParams::defaultsFor(wavog::PolicyType::kForget);
  f.policy.init = wavog::InitValue::kEmptyBound;
  EXPECT_EQ(f.initValue(), f.sensor.odd_emp);
}

}  // namespace
