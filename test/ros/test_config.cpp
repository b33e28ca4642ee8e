// The one parameter loader: shipped files load and validate, default.yaml equals the compiled
// defaults key by key, unknown keys are reported, bad values name the parameter and its range.
#include <dirent.h>
#include <gtest/gtest.h>
#include <ros/names.h>

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "wavog_mapping/ros/config.h"

namespace wavog_ros {
namespace {

const std::string kConfigDir = std::string(WAVOG_SOURCE_DIR) + "/config";

Config fromYaml(const std::string& text, std::vector<std::string>* unknown = nullptr) {
  XmlRpc::XmlRpcValue root = yamlToXmlRpc(text);
  return configFromXmlRpc(root, unknown);
}

std::string errorOf(const std::string& text) {
  try {
    fromYaml(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

void expectSame(const Config& a, const Config& b) {
  EXPECT_EQ(a.map.grid.resolution, b.map.grid.resolution);
  EXPECT_EQ(a.map.grid.block_levels, b.map.grid.block_levels);
  EXPECT_EQ(a.map.policy.type, b.map.policy.type);
  EXPECT_EQ(a.map.policy.gamma, b.map.policy.gamma);
  EXPECT_EQ(a.map.policy.clamp_min, b.map.policy.clamp_min);
  EXPECT_EQ(a.map.policy.clamp_max, b.map.policy.clamp_max);
  EXPECT_EQ(a.map.policy.init, b.map.policy.init);
  EXPECT_EQ(a.map.sensor.odd_occ, b.map.sensor.odd_occ);
  EXPECT_EQ(a.map.sensor.odd_emp, b.map.sensor.odd_emp);
  EXPECT_EQ(a.map.sensor.band_width, b.map.sensor.band_width);
  EXPECT_EQ(a.map.sensor.max_range, b.map.sensor.max_range);
  EXPECT_EQ(a.map.sensor.no_return_clear, b.map.sensor.no_return_clear);
  EXPECT_EQ(a.map.prune_threshold, b.map.prune_threshold);
  EXPECT_EQ(a.map.skip_tolerance, b.map.skip_tolerance);
  EXPECT_EQ(a.map.lazy_forgetting, b.map.lazy_forgetting);
  EXPECT_EQ(a.map.num_threads, b.map.num_threads);
  EXPECT_EQ(a.map.reflection, b.map.reflection);
  EXPECT_EQ(a.map.ndt, b.map.ndt);
  EXPECT_EQ(a.map.ndt_min_weight, b.map.ndt_min_weight);
  EXPECT_EQ(a.map.ndt_max_weight, b.map.ndt_max_weight);
  EXPECT_EQ(a.ros.map_frame, b.ros.map_frame);
  EXPECT_EQ(a.ros.base_frame, b.ros.base_frame);
  ASSERT_EQ(a.ros.inputs.size(), b.ros.inputs.size());
  for (std::size_t i = 0; i < a.ros.inputs.size(); ++i) {
    EXPECT_EQ(a.ros.inputs[i].topic, b.ros.inputs[i].topic);
    EXPECT_EQ(a.ros.inputs[i].expected_rate, b.ros.inputs[i].expected_rate);
  }
  EXPECT_EQ(a.ros.publish_rate, b.ros.publish_rate);
  EXPECT_EQ(a.ros.publish_scales, b.ros.publish_scales);
  EXPECT_EQ(a.ros.scale_aggregation, b.ros.scale_aggregation);
  EXPECT_EQ(a.ros.grid_values.trinary, b.ros.grid_values.trinary);
  EXPECT_EQ(a.ros.grid_values.occupied_thresh, b.ros.grid_values.occupied_thresh);
  EXPECT_EQ(a.ros.grid_values.free_thresh, b.ros.grid_values.free_thresh);
  EXPECT_EQ(a.ros.publish_window, b.ros.publish_window);
  EXPECT_EQ(a.ros.fleet_stream_format, b.ros.fleet_stream_format);
  EXPECT_EQ(a.ros.update_rate, b.ros.update_rate);
  EXPECT_EQ(a.ros.tf_tolerance, b.ros.tf_tolerance);
  EXPECT_EQ(a.ros.tf_cache_time, b.ros.tf_cache_time);
  EXPECT_EQ(a.ros.queue_size, b.ros.queue_size);
  EXPECT_EQ(a.ros.subscriber_queue_size, b.ros.subscriber_queue_size);
  EXPECT_EQ(a.ros.motion_compensation, b.ros.motion_compensation);
  EXPECT_EQ(a.ros.max_sensor_speed, b.ros.max_sensor_speed);
  EXPECT_EQ(a.ros.map_file, b.ros.map_file);
  EXPECT_EQ(a.ros.rate_tolerance, b.ros.rate_tolerance);
}

TEST(Config, DefaultYamlEqualsCompiledDefaults) {
  std::vector<std::string> unknown;
  const Config file = loadConfigFile(kConfigDir + "/default.yaml", &unknown);
  EXPECT_TRUE(unknown.empty());
  XmlRpc::XmlRpcValue empty;
  expectSame(file, configFromXmlRpc(empty, nullptr));
  // The compiled defaults are the "forget" policy's.
  const wavog::MapParams forget = wavog::MapParams::defaultsFor(wavog::PolicyType::kForget);
  EXPECT_EQ(file.map.sensor.odd_occ, forget.sensor.odd_occ);
  EXPECT_EQ(file.map.policy.gamma, forget.policy.gamma);
}

TEST(Config, DefaultYamlListsEveryKnownKey) {
  std::ifstream in(kConfigDir + "/default.yaml");
  std::stringstream text;
  text << in.rdbuf();
  XmlRpc::XmlRpcValue file = yamlToXmlRpc(text.str());
  std::set<std::string> in_file;
  for (auto& member : file) in_file.insert(member.first);
  const std::set<std::string> known(knownKeys().begin(), knownKeys().end());
  EXPECT_EQ(in_file, known);
}

TEST(Config, EveryShippedFileLoads) {
  DIR* dir = opendir(kConfigDir.c_str());
  ASSERT_NE(dir, nullptr);
  int files = 0;
  while (dirent* entry = readdir(dir)) {
    const std::string name = entry->d_name;
    if (name.size() < 5 || name.substr(name.size() - 5) != ".yaml") continue;
    std::vector<std::string> unknown;
    EXPECT_NO_THROW(loadConfigFile(kConfigDir + "/" + name, &unknown)) << name;
    EXPECT_TRUE(unknown.empty()) << name << ": unknown key " << unknown.front();
    ++files;
  }
  closedir(dir);
  EXPECT_GE(files, 2);
}

TEST(Config, PolicySelectsItsDefaults) {
  const Config c = fromYaml("policy: clamp");
  const wavog::MapParams d = wavog::MapParams::defaultsFor(wavog::PolicyType::kClamp);
  EXPECT_EQ(c.map.policy.type, wavog::PolicyType::kClamp);
  EXPECT_EQ(c.map.sensor.odd_occ, d.sensor.odd_occ);
  EXPECT_EQ(c.map.sensor.odd_emp, d.sensor.odd_emp);
  // An explicit key still wins over the policy default.
  EXPECT_EQ(fromYaml("{policy: clamp, odd_occ: 1.5}").map.sensor.odd_occ, 1.5);
}

TEST(Config, ReadsInputsAndLists) {
  const Config c = fromYaml(R"(
inputs: [{topic: a, expected_rate: 37.5}, b]
publish_scales: [1, 5]
scale_aggregation: max
resolution: 1
)");
  ASSERT_EQ(c.ros.inputs.size(), 2u);
  EXPECT_EQ(c.ros.inputs[0].topic, "a");
  EXPECT_EQ(c.ros.inputs[0].expected_rate, 37.5);
  EXPECT_EQ(c.ros.inputs[1].topic, "b");
  EXPECT_EQ(c.ros.publish_scales, (std::vector<int>{1, 5}));
  EXPECT_EQ(c.ros.scale_aggregation, wavog::Aggregation::kMax);
  EXPECT_EQ(c.map.grid.resolution, 1.0);  // an int is accepted for a double
}

TEST(Config, ReadsTheNdtKeys) {
  const Config off = fromYaml("{}");
  EXPECT_FALSE(off.map.ndt);  // off by default
  const Config c = fromYaml("{ndt: true, ndt_min_weight: 0.5, ndt_max_weight: 20}");
  EXPECT_TRUE(c.map.ndt);
  EXPECT_EQ(c.map.ndt_min_weight, 0.5);
  EXPECT_EQ(c.map.ndt_max_weight, 20.0);
  EXPECT_NE(errorOf("ndt: 1").find("'ndt'"), std::string::npos);
  EXPECT_NE(errorOf("ndt_min_weight: -1").find("ndt_min_weight (-1) must be in [0, 1e6]"),
            std::string::npos);
  EXPECT_NE(errorOf("ndt_max_weight: 0.5").find("ndt_max_weight (0.5) must be in [1, 1e9]"),
            std::string::npos);
}

TEST(Config, FleetRegionIsTheCoresBlockRegionOrAClearError) {
  EXPECT_TRUE(fromYaml("{}").map.region.all);  // everything by default
  // Blocks of 0.1 m x 2^4 = 1.6 m.
  const Config c = fromYaml("{resolution: 0.1, block_levels: 4, fleet_region: [-3.2, 0, 4.8, 16]}");
  EXPECT_FALSE(c.map.region.all);
  EXPECT_EQ(c.map.region.min_bx, -2);
  EXPECT_EQ(c.map.region.min_by, 0);
  EXPECT_EQ(c.map.region.max_bx, 3);
  EXPECT_EQ(c.map.region.max_by, 10);
  const std::string form = "fleet_region must be [] (everything) or [min_x, min_y, max_x, max_y]";
  const std::string unaligned =
      errorOf("{resolution: 0.1, block_levels: 4, fleet_region: [-3.2, 0, 5, 16]}");
  EXPECT_NE(unaligned.find(form), std::string::npos) << unaligned;
  EXPECT_NE(unaligned.find("1.6 m"), std::string::npos) << unaligned;
  EXPECT_NE(unaligned.find("5 is not a multiple"), std::string::npos) << unaligned;
  EXPECT_NE(errorOf("{resolution: 0.1, block_levels: 4, fleet_region: [0, 0, 1.6]}").find(form),
            std::string::npos);
  EXPECT_NE(errorOf("{resolution: 0.1, block_levels: 4, fleet_region: [3.2, 0, 1.6, 1.6]}")
                .find("min must be below max"),
            std::string::npos);
  EXPECT_NE(errorOf("{fleet_region: [0, 0, .nan, 1]}").find("fleet_region"), std::string::npos);
  EXPECT_NE(errorOf("{fleet_region: 3}").find("'fleet_region'"), std::string::npos);
  // Beyond the extent (issue 42): fleet_region names it and the extent, not the core's
  // "region (blocks ...)".
  for (const std::string yaml : {"{resolution: 1, block_levels: 2, fleet_region: [0, 0, 4e9, 4]}",
                                 "{block_levels: 7, fleet_region: [0, 0, 1.0e+12, 6.4]}",
                                 "{block_levels: 7, fleet_region: [-53687097.6, 0, 6.4, 6.4]}"}) {
    const std::string why = errorOf(yaml);
    EXPECT_NE(why.find(form), std::string::npos) << why;
    EXPECT_NE(why.find("beyond the map's extent"), std::string::npos) << why;
    EXPECT_EQ(why.find("region (blocks"), std::string::npos) << why;
  }
  // The extent itself: 2^30 cells of 5 cm, 53,687,091.2 m.
  const std::string edge = "{block_levels: 7, fleet_region: [-53687091.2, 0, 6.4, 6.4]}";
  EXPECT_EQ(errorOf(edge), "");
  EXPECT_FALSE(fromYaml(edge).map.region.all);
}

TEST(Config, FleetWindowIsBoundedByTheLayerLimit) {
  EXPECT_EQ(fromYaml("{}").ros.fleet_window, 0.0);  // off by default
  EXPECT_EQ(fromYaml("{fleet_window: 25}").ros.fleet_window, 25.0);
  // 4094 cells of 5 cm / 2: 102.35 m.
  EXPECT_NE(errorOf("{fleet_window: 103}").find("fleet_window (103) must be in [0, 102.35] m"),
            std::string::npos)
      << errorOf("{fleet_window: 103}");
  EXPECT_NE(errorOf("{fleet_window: -1}").find("fleet_window"), std::string::npos);
}

TEST(Config, FleetStreamFormatIsOneOfTwo) {
  EXPECT_EQ(fromYaml("{}").ros.fleet_stream_format, "uint16");  // 16-bit codes by default
  EXPECT_EQ(fromYaml("{fleet_stream_format: float32}").ros.fleet_stream_format, "float32");
  EXPECT_NE(errorOf("{fleet_stream_format: float64}")
                .find("fleet_stream_format ('float64') must be one of: uint16"),
            std::string::npos)
      << errorOf("{fleet_stream_format: float64}");
  EXPECT_NE(errorOf("{fleet_stream_format: 16}").find("fleet_stream_format"), std::string::npos);
}

TEST(Config, FleetReorderMaxWaitIsAtLeastTheWait) {
  EXPECT_EQ(errorOf("{fleet_reorder_wait: 0.5, fleet_reorder_max_wait: 0.5}"), "");
  EXPECT_EQ(errorOf("{fleet_reorder_max_wait: 600}"), "");
  const std::string low = errorOf("{fleet_reorder_wait: 2, fleet_reorder_max_wait: 1}");
  EXPECT_NE(low.find("fleet_reorder_max_wait (1) must be in [fleet_reorder_wait (2), 600] s"),
            std::string::npos)
      << low;
  EXPECT_NE(errorOf("{fleet_reorder_max_wait: 601}").find("fleet_reorder_max_wait (601)"),
            std::string::npos);
  EXPECT_NE(errorOf("{fleet_reorder_max_wait: .nan}").find("fleet_reorder_max_wait"),
            std::string::npos);
}

TEST(Config, ReportsUnknownKeys) {
  std::vector<std::string> unknown;
  fromYaml("{resolutoin: 0.1, publish_rate: 2}", &unknown);
  ASSERT_EQ(unknown.size(), 1u);
  EXPECT_EQ(unknown[0], "resolutoin");
}

TEST(Config, BadValuesNameTheParameterAndItsRange) {
  EXPECT_NE(errorOf("resolution: -1").find("resolution"), std::string::npos);
  EXPECT_NE(errorOf("publish_rate: 0").find("publish_rate (0) must be in (0, 100]"),
            std::string::npos);
  EXPECT_NE(errorOf("publish_scales: [0]").find("publish_scales"), std::string::npos);
  EXPECT_NE(errorOf("publish_scales: [12]").find("block_levels"), std::string::npos);
  EXPECT_NE(errorOf("inputs: []").find("1 to 4"), std::string::npos);
  EXPECT_NE(errorOf("inputs: [a, b, c, d, e]").find("1 to 4"), std::string::npos);
  EXPECT_NE(errorOf("inputs: [a, a]").find("twice"), std::string::npos);
  EXPECT_NE(errorOf("queue_size: 0").find("queue_size (0) must be in [1, 1000]"),
            std::string::npos);
  EXPECT_NE(
      errorOf("subscriber_queue_size: 0").find("subscriber_queue_size (0) must be in [1, 100000]"),
      std::string::npos);
  EXPECT_NE(errorOf("tf_tolerance: 2").find("tf_tolerance"), std::string::npos);
  EXPECT_NE(errorOf("map_frame: /map").find("map_frame"), std::string::npos);
  EXPECT_NE(errorOf("policy: forgetful").find("policy"), std::string::npos);
  EXPECT_NE(errorOf("scale_aggregation: median").find("mean, max"), std::string::npos);
  EXPECT_NE(errorOf("map_values: binary").find("trinary, graded"), std::string::npos);
  EXPECT_NE(errorOf("occupied_thresh: 0.4").find("occupied_thresh (0.4) must be in [0.5, 1]"),
            std::string::npos);
  EXPECT_NE(errorOf("free_thresh: .nan").find("free_thresh (nan) must be in [0, 0.5]"),
            std::string::npos);
  EXPECT_NE(errorOf("resolution: abc").find("'resolution'"), std::string::npos);
  EXPECT_NE(errorOf("queue_size: 2.5").find("integer"), std::string::npos);
  EXPECT_NE(errorOf("max_sensor_speed: 0").find("max_sensor_speed (0) must be in (0, 1000] m/s"),
            std::string::npos);
  EXPECT_NE(errorOf("max_sensor_speed: .nan").find("max_sensor_speed"), std::string::npos);
  EXPECT_NE(errorOf("motion_compensation: 1").find("true or false"), std::string::npos);
  EXPECT_NE(errorOf("gamma: 0").find("gamma"), std::string::npos);
  EXPECT_NE(errorOf("num_threads: -1").find("num_threads (-1) must be an integer in [0, 256]"),
            std::string::npos);
  EXPECT_NE(errorOf("inputs: [{topic: a, rate: 3}]").find("unknown key 'rate'"), std::string::npos);
}

// Issue 41, item 8: a bad resolution is one error (the limits that depend on it are not checked
// with it); a number YAML 1.1 reads as a string says so.
TEST(Config, ABadResolutionIsOneErrorAndYaml11NumbersGetAHint) {
  for (const std::string yaml :
       {"resolution: -1", "resolution: 0", "resolution: .nan",
        "{resolution: -1, fleet_window: 4, fleet_region: [0, 0, 6.4, 6.4]}"}) {
    const std::string why = errorOf(yaml);
    std::size_t lines = 0;
    for (std::size_t at = why.find("\n  "); at != std::string::npos;
         at = why.find("\n  ", at + 1)) {
      ++lines;
    }
    EXPECT_EQ(lines, 1u) << yaml << ": " << why;
    EXPECT_NE(why.find("resolution"), std::string::npos) << why;
    EXPECT_EQ(why.find("fleet_window"), std::string::npos) << why;
  }
  // rosparam's YAML 1.1 hands 5e-2 over as the string "5e-2".
  const std::string why = errorOf("resolution: '5e-2'");
  EXPECT_NE(why.find("parameter 'resolution' ('5e-2') must be a number: YAML 1.1"),
            std::string::npos)
      << why;
  EXPECT_NE(why.find("write 0.05 or 5.0e-2"), std::string::npos) << why;
  EXPECT_NE(errorOf("gamma: '1e-1'").find("write 0.1 or 1.0e-1"), std::string::npos);
  EXPECT_NE(errorOf("gamma: '2.5e3'").find("write 2500 or 2.5e+3"), std::string::npos);
  EXPECT_EQ(errorOf("gamma: abc").find("YAML 1.1"), std::string::npos);
}

// Issue 41, item 6: two inputs that are one topic once resolved are refused naming inputs.
TEST(Config, InputsThatResolveToOneTopicAreRefused) {
  const auto in_ns = [](const std::string& ns) {
    return [ns](const std::string& t) { return ros::names::resolve(ns, t, false); };
  };
  const Config c = fromYaml("inputs: [{topic: scan}, {topic: /scan}]");  // valid as written
  const std::string why = duplicateInputs(c.ros.inputs, in_ns("/"));
  EXPECT_EQ(why,
            "inputs[0].topic ('scan') and inputs[1].topic ('/scan') are one topic, /scan, in "
            "this namespace: every scan would be integrated twice; list each topic once in "
            "inputs");
  EXPECT_EQ(duplicateInputs(c.ros.inputs, in_ns("/robot")), "");  // /robot/scan and /scan
  EXPECT_NE(duplicateInputs(fromYaml("inputs: [a, b, /robot/a]").ros.inputs, in_ns("/robot")), "");
  EXPECT_EQ(duplicateInputs(fromYaml("inputs: [a, b, c, d]").ros.inputs, in_ns("/")), "");
}

TEST(Config, MissingOrMalformedFileIsAClearError) {
  try {
    loadConfigFile("/nonexistent/x.yaml", nullptr);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/x.yaml"), std::string::npos);
  }
  EXPECT_THROW(yamlToXmlRpc("a: [1, 2"), std::invalid_argument);
}

}  // namespace
}  // namespace wavog_ros
