// cfg/Mapping.cfg against the validation (no master needed): for every number of the .cfg, a
// value just outside its [min, max] is refused naming the parameter, one just inside is accepted,
// so the ranges rqt_reconfigure shows are the ranges validate() enforces; the mapping to Config
// goes both ways; bad policy, init and scales strings are refused.
#include <gtest/gtest.h>

#include <boost/any.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "../../src/ros/reconfigure.h"

namespace {

using wavog_mapping::MappingConfig;

MappingConfig with(const MappingConfig& base, const std::string& name, double value) {
  MappingConfig rc = base;
  dynamic_reconfigure::Config msg;
  dynamic_reconfigure::DoubleParameter p;
  p.name = name;
  p.value = value;
  msg.doubles.push_back(p);
  EXPECT_TRUE(rc.__fromMessage__(msg)) << name;
  return rc;
}

/// The errors naming `name` when `name` is set to `value` on the default configuration.
std::vector<std::string> errorsFor(const std::string& name, double value) {
  const wavog_ros::Config base;
  std::vector<std::string> errors;
  wavog_ros::withReconfigure(base, with(wavog_ros::toReconfigure(base), name, value), &errors);
  std::vector<std::string> named;
  for (const auto& e : errors) {
    if (e.compare(0, name.size() + 1, name + " ") == 0) named.push_back(e);
  }
  EXPECT_EQ(named.size(), errors.size()) << name << " = " << value << ": " << errors.front();
  return named;
}

double number(const MappingConfig& c, const MappingConfig::AbstractParamDescriptionConstPtr& d) {
  boost::any v;
  d->getValue(c, v);
  return boost::any_cast<double>(v);
}

TEST(ReconfigureRanges, CfgRangesAreTheValidatedRanges) {
  int numbers = 0;
  for (const auto& d : MappingConfig::__getParamDescriptions__()) {
    if (d->type != "double") continue;
    ++numbers;
    const double lo = number(MappingConfig::__getMin__(), d);
    const double hi = number(MappingConfig::__getMax__(), d);
    const auto step = [](double bound) { return std::max(1e-6, std::abs(bound) * 1e-6); };
    if (std::isfinite(lo)) {
      EXPECT_FALSE(errorsFor(d->name, lo - step(lo)).empty()) << d->name << " below min " << lo;
      EXPECT_TRUE(errorsFor(d->name, lo + step(lo)).empty()) << d->name << " just above min";
    } else {
      EXPECT_TRUE(errorsFor(d->name, -1e6).empty()) << d->name << ": no min, but -1e6 refused";
    }
    if (std::isfinite(hi)) {
      EXPECT_FALSE(errorsFor(d->name, hi + step(hi)).empty()) << d->name << " above max " << hi;
      EXPECT_TRUE(errorsFor(d->name, hi - step(hi)).empty()) << d->name << " just below max";
    } else {
      EXPECT_TRUE(errorsFor(d->name, 1e6).empty()) << d->name << ": no max, but 1e6 refused";
    }
  }
  EXPECT_GE(numbers, 6);
}

TEST(ReconfigureRanges, RefusalNamesTheRange) {
  const auto e = errorsFor("odd_occ", -1.0);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("(0, 50]"), std::string::npos) << e[0];
}

TEST(ReconfigureRanges, PolicyAndInitBothWays) {
  wavog_ros::Config base;
  MappingConfig rc = wavog_ros::toReconfigure(base);
  EXPECT_EQ(rc.policy, "forget");
  EXPECT_EQ(rc.init, "unknown");
  rc.policy = "clamp";
  rc.init = "empty_bound";
  std::vector<std::string> errors;
  const wavog_ros::Config next = wavog_ros::withReconfigure(base, rc, &errors);
  EXPECT_TRUE(errors.empty());
  EXPECT_EQ(next.map.policy.type, wavog::PolicyType::kClamp);
  EXPECT_EQ(next.map.policy.init, wavog::InitValue::kEmptyBound);
  EXPECT_EQ(wavog_ros::toReconfigure(next).policy, "clamp");

  rc.policy = "forgett";
  rc.init = "zero";
  rc.scales = "2,x";
  errors.clear();
  wavog_ros::withReconfigure(base, rc, &errors);
  ASSERT_EQ(errors.size(), 3u);
  EXPECT_EQ(errors[0].compare(0, 7, "scales "), 0) << errors[0];
  EXPECT_EQ(errors[1].compare(0, 7, "policy "), 0) << errors[1];
  EXPECT_EQ(errors[2].compare(0, 5, "init "), 0) << errors[2];
}

// Issue 41: a refused scale names the reconfigure key, `scales`, not the file's publish_scales.
TEST(Reconfigure, ARefusedScaleNamesTheKeyScales) {
  const wavog_ros::Config base;
  MappingConfig rc = wavog_ros::toReconfigure(base);
  rc.scales = "2,13";
  std::vector<std::string> errors;
  wavog_ros::withReconfigure(base, rc, &errors);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].rfind("scales entry (13) must be in [1, block_levels", 0), 0u) << errors[0];
}

}  // namespace
