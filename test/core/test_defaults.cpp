// One source of defaults: the field initialisers of params.h. defaultsFor() is derived from them;
// config/default.yaml and cfg/Mapping.cfg (dynamic_reconfigure) repeat them and are checked here,
// as text, without ROS.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>

#include "wavog_mapping/core/params.h"

namespace {

using wavog::MapParams;
using wavog::PolicyType;

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The core's keys and their compiled defaults, as the configuration files spell them.
std::map<std::string, std::string> coreDefaults() {
  const MapParams d;
  auto num = [](double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  };
  return {{"resolution", num(d.grid.resolution)},
          {"block_levels", num(d.grid.block_levels)},
          {"policy", wavog::toString(d.policy.type)},
          {"gamma", num(d.policy.gamma)},
          {"forget_half_life", num(d.policy.forget_half_life)},
          {"clamp_min", num(d.policy.clamp_min)},
          {"clamp_max", num(d.policy.clamp_max)},
          {"init", wavog::toString(d.policy.init)},
          {"odd_occ", num(d.sensor.odd_occ)},
          {"odd_emp", num(d.sensor.odd_emp)},
          {"band_width", num(d.sensor.band_width)},
          {"max_range", num(d.sensor.max_range)},
          {"no_return_clear", num(d.sensor.no_return_clear)},
          {"prune_threshold", num(d.prune_threshold)},
          {"skip_tolerance", num(d.skip_tolerance)},
          {"lazy_forgetting", d.lazy_forgetting ? "true" : "false"},
          {"num_threads", num(d.num_threads)},
          {"reflection", d.reflection ? "true" : "false"}};
}

// A number as written in a file, normalised like num() above ("0.0" -> "0", "-2.0" -> "-2").
std::string normalised(const std::string& text) {
  if (text == "true" || text == "false") return text;
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used != text.size()) return text;
    std::ostringstream s;
    s << v;
    return s.str();
  } catch (const std::exception&) {
    return text;
  }
}

TEST(Defaults, DefaultsForIsTheFieldInitialisersPerPolicy) {
  const MapParams d;
  for (auto t : {PolicyType::kNone, PolicyType::kMax, PolicyType::kClamp, PolicyType::kForget,
                 PolicyType::kClampLower, PolicyType::kClampUpper}) {
    const MapParams p = MapParams::defaultsFor(t);
    EXPECT_EQ(p.policy.type, t);
    const bool forget = t == PolicyType::kForget;
    EXPECT_EQ(p.sensor.odd_occ,
              forget ? d.sensor.odd_occ : wavog::SensorModelParams::kAdditiveOddOcc);
    EXPECT_EQ(p.sensor.odd_emp,
              forget ? d.sensor.odd_emp : wavog::SensorModelParams::kAdditiveOddEmp);
    EXPECT_EQ(p.policy.gamma, d.policy.gamma);
    EXPECT_EQ(p.policy.clamp_min, d.policy.clamp_min);
    EXPECT_EQ(p.policy.clamp_max, d.policy.clamp_max);
    EXPECT_EQ(p.grid.resolution, d.grid.resolution);
    EXPECT_EQ(p.prune_threshold, d.prune_threshold);
  }
  EXPECT_EQ(d.policy.type, PolicyType::kForget);
}

TEST(Defaults, DefaultYamlRepeatsTheFieldInitialisers) {
  const std::string text = readFile(std::string(WAVOG_SOURCE_DIR) + "/config/default.yaml");
  ASSERT_FALSE(text.empty());
  const std::regex line(R"(^([a-z_]+):\s*([^\s#]+))");
  std::map<std::string, std::string> file;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) {
    std::smatch m;
    if (std::regex_search(l, m, line)) file[m[1]] = normalised(m[2]);
  }
  for (const auto& kv : coreDefaults()) {
    ASSERT_TRUE(file.count(kv.first)) << kv.first << " missing from default.yaml";
    EXPECT_EQ(file[kv.first], kv.second) << kv.first;
  }
  // The comment naming the other policies' odd values.
  std::ostringstream other;
  other << "odd_occ " << wavog::SensorModelParams::kAdditiveOddOcc << ", odd_emp "
        << wavog::SensorModelParams::kAdditiveOddEmp;
  EXPECT_NE(text.find(other.str()), std::string::npos) << other.str();
}

TEST(Defaults, ReconfigureDefaultsRepeatTheFieldInitialisers) {
  const std::string text = readFile(std::string(WAVOG_SOURCE_DIR) + "/cfg/Mapping.cfg");
  ASSERT_FALSE(text.empty());
  // gen.add("name", type, level, "description", default, min, max)
  const std::regex add(
      R"re(gen\.add\("([a-z_]+)",\s*double_t,\s*\d+,\s*"[^"]*",\s*([-0-9.e]+),)re");
  const auto defaults = coreDefaults();
  int checked = 0;
  for (std::sregex_iterator it(text.begin(), text.end(), add), end; it != end; ++it) {
    const std::string name = (*it)[1];
    if (!defaults.count(name)) continue;  // a ROS-side parameter
    EXPECT_EQ(normalised((*it)[2]), defaults.at(name)) << name;
    ++checked;
  }
  EXPECT_EQ(checked, 6);  // gamma, forget_half_life, clamp_min, clamp_max, odd_occ, odd_emp
}

}  // namespace
