// The one parameter loader (see config.h). Each key is read by exactly one entry of kReaders, so
// the list of known keys, the type checks and the error messages cannot drift apart.
#include "wavog_mapping/ros/config.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <stdexcept>

namespace wavog_ros {
namespace {

using XmlRpc::XmlRpcValue;

std::string describe(XmlRpcValue& v) {
  std::ostringstream os;
  v.write(os);
  return os.str();
}

[[noreturn]] void typeError(const std::string& key, XmlRpcValue& v, const char* expected) {
  throw std::invalid_argument("parameter '" + key + "' (" + describe(v) + ") must be " + expected);
}

// A string that reads as a number: rosparam's YAML 1.1 takes 5e-2 (no '.' in the mantissa, or no
// sign in the exponent) for a string.
bool numberInAString(XmlRpcValue& v) {
  if (v.getType() != XmlRpcValue::TypeString) return false;
  const std::string text = static_cast<std::string>(v);
  char* end = nullptr;
  std::strtod(text.c_str(), &end);
  return !text.empty() && end == text.c_str() + text.size();
}

double asDouble(const std::string& key, XmlRpcValue& v) {
  switch (v.getType()) {
    case XmlRpcValue::TypeDouble:
      return static_cast<double>(v);
    case XmlRpcValue::TypeInt:
      return static_cast<double>(static_cast<int>(v));
    default:
      if (numberInAString(v)) {
        const std::string text = static_cast<std::string>(v);
        std::ostringstream plain;
        plain << std::strtod(text.c_str(), nullptr);
        // The same in YAML 1.1's float form: a '.' in the mantissa, a signed exponent.
        std::string yaml11 = text;
        const std::size_t e = yaml11.find_first_of("eE");
        if (e != std::string::npos) {
          if (yaml11.find('.') == std::string::npos) yaml11.insert(e, ".0");
          const std::size_t sign = yaml11.find_first_of("eE") + 1;
          if (sign < yaml11.size() && yaml11[sign] != '-' && yaml11[sign] != '+') {
            yaml11.insert(sign, "+");
          }
        }
        throw std::invalid_argument("parameter '" + key + "' ('" + text +
                                    "') must be a number: YAML 1.1 (rosparam, roslaunch) reads " +
                                    text + " as a string; write " + plain.str() +
                                    (yaml11 != text ? " or " + yaml11 : std::string()));
      }
      typeError(key, v, "a number");
  }
}

int asInt(const std::string& key, XmlRpcValue& v) {
  if (v.getType() == XmlRpcValue::TypeInt) return static_cast<int>(v);
  if (v.getType() == XmlRpcValue::TypeDouble) {
    const double d = static_cast<double>(v);
    if (std::isfinite(d) && d == std::round(d) && std::abs(d) < 1e9) return static_cast<int>(d);
  }
  typeError(key, v, "an integer");
}

bool asBool(const std::string& key, XmlRpcValue& v) {
  if (v.getType() == XmlRpcValue::TypeBoolean) return static_cast<bool>(v);
  typeError(key, v, "true or false");
}

std::string asString(const std::string& key, XmlRpcValue& v) {
  if (v.getType() == XmlRpcValue::TypeString) return static_cast<std::string>(v);
  typeError(key, v, "a string");
}

std::vector<InputConfig> asInputs(const std::string& key, XmlRpcValue& v) {
  if (v.getType() != XmlRpcValue::TypeArray) {
    typeError(key, v, "a list of {topic: <name>, expected_rate: <Hz>} (1 to 4 entries)");
  }
  std::vector<InputConfig> inputs;
  for (int i = 0; i < v.size(); ++i) {
    const std::string item_key = key + "[" + std::to_string(i) + "]";
    XmlRpcValue& item = v[i];
    InputConfig input;
    if (item.getType() == XmlRpcValue::TypeString) {
      input.topic = static_cast<std::string>(item);
    } else if (item.getType() == XmlRpcValue::TypeStruct) {
      for (auto& member : item) {
        if (member.first == "topic") {
          input.topic = asString(item_key + ".topic", member.second);
        } else if (member.first == "expected_rate") {
          input.expected_rate = asDouble(item_key + ".expected_rate", member.second);
        } else {
          throw std::invalid_argument("parameter '" + item_key + "' has unknown key '" +
                                      member.first + "' (known: topic, expected_rate)");
        }
      }
    } else {
      typeError(item_key, item, "a topic name or {topic: <name>, expected_rate: <Hz>}");
    }
    inputs.push_back(input);
  }
  return inputs;
}

std::vector<int> asIntList(const std::string& key, XmlRpcValue& v) {
  if (v.getType() != XmlRpcValue::TypeArray) typeError(key, v, "a list of integers");
  std::vector<int> out;
  for (int i = 0; i < v.size(); ++i)
    out.push_back(asInt(key + "[" + std::to_string(i) + "]", v[i]));
  return out;
}

std::vector<std::string> asStringList(const std::string& key, XmlRpcValue& v) {
  if (v.getType() != XmlRpcValue::TypeArray) typeError(key, v, "a list of strings");
  std::vector<std::string> out;
  for (int i = 0; i < v.size(); ++i)
    out.push_back(asString(key + "[" + std::to_string(i) + "]", v[i]));
  return out;
}

std::vector<double> asDoubleList(const std::string& key, XmlRpcValue& v) {
  if (v.getType() != XmlRpcValue::TypeArray) typeError(key, v, "a list of numbers");
  std::vector<double> out;
  for (int i = 0; i < v.size(); ++i) out.push_back(asDouble(key + "[" + std::to_string(i) + "]", v[i]));
  return out;
}

/// Reads one key into a Config.
struct KeyReader {
  const char* key;
  std::function<void(const std::string&, XmlRpcValue&, Config*)> read;
};

const std::vector<KeyReader>& readers() {
  // "policy" is handled first by configFromXmlRpc (it selects the defaults) and is listed here so
  // that it counts as known.
  static const std::vector<KeyReader> kReaders = {
      // ---- core: grid
      {"resolution", [](auto& k, auto& v, Config* c) { c->map.grid.resolution = asDouble(k, v); }},
      {"block_levels", [](auto& k, auto& v, Config* c) { c->map.grid.block_levels = asInt(k, v); }},
      // ---- core: policy
      {"policy", [](auto&, auto&, Config*) {}},
      {"gamma", [](auto& k, auto& v, Config* c) { c->map.policy.gamma = asDouble(k, v); }},
      {"forget_half_life",
       [](auto& k, auto& v, Config* c) { c->map.policy.forget_half_life = asDouble(k, v); }},
      {"clamp_min", [](auto& k, auto& v, Config* c) { c->map.policy.clamp_min = asDouble(k, v); }},
      {"clamp_max", [](auto& k, auto& v, Config* c) { c->map.policy.clamp_max = asDouble(k, v); }},
      {"init",
       [](auto& k, auto& v, Config* c) {
         const std::string name = asString(k, v);
         if (!wavog::fromString(name, &c->map.policy.init)) {
           throw std::invalid_argument("parameter 'init' (" + name +
                                       ") must be one of: unknown, empty_bound");
         }
       }},
      // ---- core: sensor model
      {"odd_occ", [](auto& k, auto& v, Config* c) { c->map.sensor.odd_occ = asDouble(k, v); }},
      {"odd_emp", [](auto& k, auto& v, Config* c) { c->map.sensor.odd_emp = asDouble(k, v); }},
      {"band_width",
       [](auto& k, auto& v, Config* c) { c->map.sensor.band_width = asDouble(k, v); }},
      {"max_range", [](auto& k, auto& v, Config* c) { c->map.sensor.max_range = asDouble(k, v); }},
      {"no_return_clear",
       [](auto& k, auto& v, Config* c) { c->map.sensor.no_return_clear = asDouble(k, v); }},
      // ---- core: compression and forgetting
      {"prune_threshold",
       [](auto& k, auto& v, Config* c) { c->map.prune_threshold = asDouble(k, v); }},
      {"skip_tolerance",
       [](auto& k, auto& v, Config* c) { c->map.skip_tolerance = asDouble(k, v); }},
      {"lazy_forgetting",
       [](auto& k, auto& v, Config* c) { c->map.lazy_forgetting = asBool(k, v); }},
      {"num_threads", [](auto& k, auto& v, Config* c) { c->map.num_threads = asInt(k, v); }},
      {"reflection", [](auto& k, auto& v, Config* c) { c->map.reflection = asBool(k, v); }},
      {"ndt", [](auto& k, auto& v, Config* c) { c->map.ndt = asBool(k, v); }},
      {"ndt_min_weight",
       [](auto& k, auto& v, Config* c) { c->map.ndt_min_weight = asDouble(k, v); }},
      {"ndt_max_weight",
       [](auto& k, auto& v, Config* c) { c->map.ndt_max_weight = asDouble(k, v); }},
      // ---- ROS
      {"map_frame", [](auto& k, auto& v, Config* c) { c->ros.map_frame = asString(k, v); }},
      {"base_frame", [](auto& k, auto& v, Config* c) { c->ros.base_frame = asString(k, v); }},
      {"inputs", [](auto& k, auto& v, Config* c) { c->ros.inputs = asInputs(k, v); }},
      {"publish_rate", [](auto& k, auto& v, Config* c) { c->ros.publish_rate = asDouble(k, v); }},
      {"publish_scales",
       [](auto& k, auto& v, Config* c) { c->ros.publish_scales = asIntList(k, v); }},
      {"scale_aggregation",
       [](auto& k, auto& v, Config* c) {
         const std::string name = asString(k, v);
         if (!fromString(name, &c->ros.scale_aggregation)) {
           throw std::invalid_argument("parameter 'scale_aggregation' (" + name +
                                       ") must be one of: mean, max");
         }
       }},
      {"map_values",
       [](auto& k, auto& v, Config* c) {
         const std::string name = asString(k, v);
         if (name != "trinary" && name != "graded") {
           throw std::invalid_argument("parameter 'map_values' (" + name +
                                       ") must be one of: trinary, graded");
         }
         c->ros.grid_values.trinary = name == "trinary";
       }},
      {"occupied_thresh",
       [](auto& k, auto& v, Config* c) { c->ros.grid_values.occupied_thresh = asDouble(k, v); }},
      {"free_thresh",
       [](auto& k, auto& v, Config* c) { c->ros.grid_values.free_thresh = asDouble(k, v); }},
      {"publish_window",
       [](auto& k, auto& v, Config* c) { c->ros.publish_window = asDouble(k, v); }},
      {"update_rate", [](auto& k, auto& v, Config* c) { c->ros.update_rate = asDouble(k, v); }},
      {"tf_tolerance", [](auto& k, auto& v, Config* c) { c->ros.tf_tolerance = asDouble(k, v); }},
      {"tf_cache_time", [](auto& k, auto& v, Config* c) { c->ros.tf_cache_time = asDouble(k, v); }},
      {"queue_size", [](auto& k, auto& v, Config* c) { c->ros.queue_size = asInt(k, v); }},
      {"subscriber_queue_size",
       [](auto& k, auto& v, Config* c) { c->ros.subscriber_queue_size = asInt(k, v); }},
      {"motion_compensation",
       [](auto& k, auto& v, Config* c) { c->ros.motion_compensation = asBool(k, v); }},
      {"max_sensor_speed",
       [](auto& k, auto& v, Config* c) { c->ros.max_sensor_speed = asDouble(k, v); }},
      {"map_file", [](auto& k, auto& v, Config* c) { c->ros.map_file = asString(k, v); }},
      {"map_dir", [](auto& k, auto& v, Config* c) { c->ros.map_dir = asString(k, v); }},
      {"rate_tolerance",
       [](auto& k, auto& v, Config* c) { c->ros.rate_tolerance = asDouble(k, v); }},
      {"idle_timeout", [](auto& k, auto& v, Config* c) { c->ros.idle_timeout = asDouble(k, v); }},
      // ---- the fleet (issue 30)
      {"fleet_stream", [](auto& k, auto& v, Config* c) { c->ros.fleet_stream = asBool(k, v); }},
      {"fleet_stream_format",
       [](auto& k, auto& v, Config* c) { c->ros.fleet_stream_format = asString(k, v); }},
      {"vehicle_id", [](auto& k, auto& v, Config* c) { c->ros.vehicle_id = asString(k, v); }},
      {"fleet_vehicles",
       [](auto& k, auto& v, Config* c) { c->ros.fleet_vehicles = asStringList(k, v); }},
      {"fleet_reorder_wait",
       [](auto& k, auto& v, Config* c) { c->ros.fleet_reorder_wait = asDouble(k, v); }},
      {"fleet_reorder_max_wait",
       [](auto& k, auto& v, Config* c) { c->ros.fleet_reorder_max_wait = asDouble(k, v); }},
      {"fleet_stale_timeout",
       [](auto& k, auto& v, Config* c) { c->ros.fleet_stale_timeout = asDouble(k, v); }},
      {"fleet_integrate_late",
       [](auto& k, auto& v, Config* c) { c->ros.fleet_integrate_late = asBool(k, v); }},
      {"fleet_max_buffered",
       [](auto& k, auto& v, Config* c) { c->ros.fleet_max_buffered = asInt(k, v); }},
      {"fleet_max_stamp_offset",
       [](auto& k, auto& v, Config* c) { c->ros.fleet_max_stamp_offset = asDouble(k, v); }},
      {"fleet_window",
       [](auto& k, auto& v, Config* c) { c->ros.fleet_window = asDouble(k, v); }},
      {"fleet_region",
       [](auto& k, auto& v, Config* c) { c->ros.fleet_region = asDoubleList(k, v); }},
  };
  return kReaders;
}

/// Converts one YAML node; scalars become bool, int, double or string in that order of
/// preference, except quoted scalars, which stay strings.
XmlRpcValue toXmlRpc(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Map: {
      XmlRpcValue v;
      v.begin();  // makes it an (empty) struct
      for (const auto& kv : node) v[kv.first.as<std::string>()] = toXmlRpc(kv.second);
      return v;
    }
    case YAML::NodeType::Sequence: {
      XmlRpcValue v;
      v.setSize(static_cast<int>(node.size()));
      int i = 0;
      for (const auto& item : node) v[i++] = toXmlRpc(item);
      return v;
    }
    case YAML::NodeType::Scalar: {
      const std::string text = node.Scalar();
      if (node.Tag() == "!") return XmlRpcValue(text);  // quoted
      if (text == "true" || text == "True" || text == "false" || text == "False") {
        return XmlRpcValue(text[0] == 't' || text[0] == 'T');
      }
      try {
        std::size_t used = 0;
        const long long i = std::stoll(text, &used, 10);
        if (used == text.size() && i >= INT32_MIN && i <= INT32_MAX) {
          return XmlRpcValue(static_cast<int>(i));
        }
      } catch (const std::exception&) {
      }
      double d = 0.0;
      if (YAML::convert<double>::decode(node, d)) return XmlRpcValue(d);
      return XmlRpcValue(text);
    }
    case YAML::NodeType::Null:
    case YAML::NodeType::Undefined:
    default:
      return XmlRpcValue();
  }
}

}  // namespace

const char* toString(wavog::Aggregation aggregation) {
  return aggregation == wavog::Aggregation::kMax ? "max" : "mean";
}

bool fromString(const std::string& name, wavog::Aggregation* aggregation) {
  if (name == "mean") {
    *aggregation = wavog::Aggregation::kMean;
  } else if (name == "max") {
    *aggregation = wavog::Aggregation::kMax;
  } else {
    return false;
  }
  return true;
}

const std::vector<std::string>& knownKeys() {
  static const std::vector<std::string> kKeys = [] {
    std::vector<std::string> keys;
    for (const auto& r : readers()) keys.emplace_back(r.key);
    return keys;
  }();
  return kKeys;
}


Config configFromXmlRpc(XmlRpc::XmlRpcValue& root, std::vector<std::string>* unknown_keys) {
  Config config;
  if (root.getType() != XmlRpcValue::TypeStruct && root.getType() != XmlRpcValue::TypeInvalid) {
    throw std::invalid_argument("the configuration must be a map of parameters, got " +
                                describe(root));
  }
  wavog::PolicyType policy = wavog::PolicyType::kForget;
  if (root.getType() == XmlRpcValue::TypeStruct && root.hasMember("policy")) {
    const std::string name = asString("policy", root["policy"]);
    if (!wavog::fromString(name, &policy)) {
      throw std::invalid_argument("parameter 'policy' (" + name +
                                  ") must be one of: none, max, clamp, forget, clamp_lower, "
                                  "clamp_upper");
    }
  }
  config.map = wavog::MapParams::defaultsFor(policy);
  config.map.policy.type = policy;

  if (root.getType() == XmlRpcValue::TypeStruct) {
    for (auto& member : root) {
      const auto& rs = readers();
      auto it = std::find_if(rs.begin(), rs.end(),
                             [&](const KeyReader& r) { return member.first == r.key; });
      if (it == rs.end()) {
        if (unknown_keys) unknown_keys->push_back(member.first);
        continue;
      }
      it->read(member.first, member.second, &config);
    }
  }

  if (config.ros.fleet_region.size() == 4) {
    // The core's region (its extent is checked by MapParams::validate; the form by validate()).
    std::string why;
    wavog::BlockRegion r;
    if (fleetRegionBlocks(config.ros.fleet_region, config.map.grid, &r, &why)) config.map.region = r;
  }
  std::vector<std::string> errors = config.map.validate();
  const std::vector<std::string> ros_errors = validate(config.ros, config.map);
  errors.insert(errors.end(), ros_errors.begin(), ros_errors.end());
  if (!errors.empty()) {
    std::string message = "invalid configuration:";
    for (const auto& line : errors) message += "\n  " + line;
    throw std::invalid_argument(message);
  }
  return config;
}

Config loadConfig(const ros::NodeHandle& pnh, std::vector<std::string>* unknown_keys) {
  XmlRpcValue root;
  if (!pnh.getParam(pnh.getNamespace(), root)) root = XmlRpcValue();
  std::vector<std::string> unknown;
  Config config = configFromXmlRpc(root, &unknown);
  // dynamic_reconfigure mirrors its "scales" string into ~ (a restarted node finds it there).
  for (const auto& key : unknown) {
    if (key != "scales" && unknown_keys) unknown_keys->push_back(key);
  }
  return config;
}

XmlRpc::XmlRpcValue yamlToXmlRpc(const std::string& yaml_text) {
  YAML::Node node;
  try {
    node = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(std::string("malformed YAML: ") + e.what());
  }
  return toXmlRpc(node);
}

Config loadConfigFile(const std::string& yaml_path, std::vector<std::string>* unknown_keys) {
  std::ifstream in(yaml_path);
  if (!in) throw std::invalid_argument("cannot read configuration file '" + yaml_path + "'");
  std::stringstream text;
  text << in.rdbuf();
  XmlRpcValue root;
  try {
    root = yamlToXmlRpc(text.str());
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(yaml_path + ": " + e.what());
  }
  try {
    return configFromXmlRpc(root, unknown_keys);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(yaml_path + ": " + e.what());
  }
}

}  // namespace wavog_ros
