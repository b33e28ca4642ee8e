// The one parameter loader (see config.h). Each key is read by exactly one entry of kReaders, so
// the list of known keys, the type checks and the error messages cannot drift apart.
#include "wavog_mapping/ros/config.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
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

double asDouble(const std::string& key, XmlRpcValue& v) {
  switch (v.getType()) {
    case XmlRpcValue::TypeDouble:
      return static_cast<double>(v);
    case XmlRpcValue::TypeInt:
      return static_cast<double>(static_cast<int>(v));
    default:
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

std::string fmt(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

void check(bool ok, std::vector<std::string>* errors, const std::string& message) {
  if (!ok) errors->push_back(message);
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

std::vector<std::string> validate(const RosParams& ros, const wavog::MapParams& map) {
  std::vector<std::string> e;
  check(!ros.map_frame.empty() && ros.map_frame[0] != '/', &e,
        "map_frame ('" + ros.map_frame + "') must be a non-empty tf2 frame id without leading '/'");
  check(
      !ros.base_frame.empty() && ros.base_frame[0] != '/', &e,
      "base_frame ('" + ros.base_frame + "') must be a non-empty tf2 frame id without leading '/'");
  const int n = static_cast<int>(ros.inputs.size());
  check(n >= 1 && n <= kMaxInputs, &e,
        "inputs (" + std::to_string(n) + " entries) must have 1 to " + std::to_string(kMaxInputs) +
            " entries");
  std::set<std::string> topics;
  for (int i = 0; i < n; ++i) {
    const InputConfig& in = ros.inputs[static_cast<std::size_t>(i)];
    const std::string name = "inputs[" + std::to_string(i) + "]";
    check(!in.topic.empty(), &e, name + ".topic must be a non-empty topic name");
    check(topics.insert(in.topic).second, &e, name + ".topic ('" + in.topic + "') is listed twice");
    check(std::isfinite(in.expected_rate) && in.expected_rate >= 0.0 && in.expected_rate <= 1000.0,
          &e, name + ".expected_rate (" + fmt(in.expected_rate) + ") must be in [0, 1000] Hz");
  }
  check(std::isfinite(ros.publish_rate) && ros.publish_rate > 0.0 && ros.publish_rate <= 100.0, &e,
        "publish_rate (" + fmt(ros.publish_rate) + ") must be in (0, 100] Hz");
  std::set<int> scales;
  for (int s : ros.publish_scales) {
    check(s >= 1 && s <= map.grid.block_levels, &e,
          "publish_scales entry (" + std::to_string(s) +
              ") must be in [1, block_levels = " + std::to_string(map.grid.block_levels) + "]");
    check(scales.insert(s).second, &e,
          "publish_scales entry (" + std::to_string(s) + ") is listed twice");
  }
  check(std::isfinite(ros.publish_window) && ros.publish_window >= 0.0, &e,
        "publish_window (" + fmt(ros.publish_window) + ") must be >= 0 m (0: whole map)");
  check(std::isfinite(ros.update_rate) && ros.update_rate >= 0.0 && ros.update_rate <= 100.0, &e,
        "update_rate (" + fmt(ros.update_rate) + ") must be in [0, 100] Hz (0: off)");
  check(std::isfinite(ros.tf_tolerance) && ros.tf_tolerance >= 0.0 && ros.tf_tolerance <= 1.0, &e,
        "tf_tolerance (" + fmt(ros.tf_tolerance) + ") must be in [0, 1] s");
  check(std::isfinite(ros.tf_cache_time) && ros.tf_cache_time >= 1.0 && ros.tf_cache_time <= 3600.0,
        &e, "tf_cache_time (" + fmt(ros.tf_cache_time) + ") must be in [1, 3600] s");
  check(ros.queue_size >= 1 && ros.queue_size <= 1000, &e,
        "queue_size (" + std::to_string(ros.queue_size) + ") must be in [1, 1000]");
  check(ros.subscriber_queue_size >= 1 && ros.subscriber_queue_size <= 100000, &e,
        "subscriber_queue_size (" + std::to_string(ros.subscriber_queue_size) +
            ") must be in [1, 100000]");
  check(ros.map_dir.empty() || (ros.map_dir[0] == '/' && ("/" + ros.map_dir + "/").find("/../") ==
                                                               std::string::npos),
        &e, "map_dir ('" + ros.map_dir + "') must be an absolute path without '..' (empty: the ROS home)");
  check(std::isfinite(ros.rate_tolerance) && ros.rate_tolerance >= 0.0 && ros.rate_tolerance < 1.0,
        &e, "rate_tolerance (" + fmt(ros.rate_tolerance) + ") must be in [0, 1)");
  check(std::isfinite(ros.max_sensor_speed) && ros.max_sensor_speed > 0.0 &&
            ros.max_sensor_speed <= 1000.0,
        &e, "max_sensor_speed (" + fmt(ros.max_sensor_speed) + ") must be in (0, 1000] m/s");
  check(std::isfinite(ros.idle_timeout) && ros.idle_timeout >= 0.0 && ros.idle_timeout <= 3600.0,
        &e, "idle_timeout (" + fmt(ros.idle_timeout) + ") must be in [0, 3600] s (0: never)");
  check(static_cast<int>(ros.fleet_vehicles.size()) <= kMaxFleetVehicles, &e,
        "fleet_vehicles (" + std::to_string(ros.fleet_vehicles.size()) + " entries) must have at most " +
            std::to_string(kMaxFleetVehicles) + " namespaces");
  std::set<std::string> vehicles;
  for (const std::string& v : ros.fleet_vehicles) {
    check(!v.empty(), &e, "fleet_vehicles entry must be a non-empty namespace");
    check(vehicles.insert(v).second, &e, "fleet_vehicles entry ('" + v + "') is listed twice");
  }
  check(ros.fleet_stream_format == "uint16" || ros.fleet_stream_format == "float32", &e,
        "fleet_stream_format ('" + ros.fleet_stream_format +
            "') must be one of: uint16 (16-bit range codes, the default), float32");
  check(std::isfinite(ros.fleet_reorder_wait) && ros.fleet_reorder_wait >= 0.0 &&
            ros.fleet_reorder_wait <= 10.0,
        &e, "fleet_reorder_wait (" + fmt(ros.fleet_reorder_wait) + ") must be in [0, 10] s");
  check(std::isfinite(ros.fleet_stale_timeout) && ros.fleet_stale_timeout > 0.0 &&
            ros.fleet_stale_timeout <= 3600.0,
        &e, "fleet_stale_timeout (" + fmt(ros.fleet_stale_timeout) + ") must be in (0, 3600] s");
  check(ros.fleet_max_buffered >= 1 && ros.fleet_max_buffered <= 1000000, &e,
        "fleet_max_buffered (" + std::to_string(ros.fleet_max_buffered) +
            ") must be in [1, 1000000]");
  check(std::isfinite(ros.fleet_max_stamp_offset) && ros.fleet_max_stamp_offset > 0.0 &&
            ros.fleet_max_stamp_offset <= 86400.0,
        &e, "fleet_max_stamp_offset (" + fmt(ros.fleet_max_stamp_offset) +
                ") must be in (0, 86400] s");
  // A window of half-width w holds (2 w / resolution + 2)^2 cells at most (kMaxLayerCells).
  const double max_window = 0.5 * (4096.0 - 2.0) * map.grid.resolution;  // 4096^2 = 2^24 cells
  check(std::isfinite(ros.fleet_window) && ros.fleet_window >= 0.0 &&
            ros.fleet_window <= max_window,
        &e, "fleet_window (" + fmt(ros.fleet_window) + ") must be in [0, " + fmt(max_window) +
                "] m (0: off; the window must hold at most 2^24 cells)");
  if (!ros.fleet_region.empty()) {
    std::string why;
    wavog::BlockRegion r;
    if (ros.fleet_region.size() != 4) {
      why = "it has " + std::to_string(ros.fleet_region.size()) + " values";
    } else {
      fleetRegionBlocks(ros.fleet_region, map.grid, &r, &why);
    }
    check(why.empty(), &e,
          "fleet_region must be [] (everything) or [min_x, min_y, max_x, max_y] in m, min < max, "
          "each a multiple of the block size (resolution x 2^block_levels = " +
              fmt(map.grid.resolution * std::ldexp(1.0, map.grid.block_levels)) + " m): " + why);
  }
  return e;
}

bool fleetRegionBlocks(const std::vector<double>& region, const wavog::GridParams& grid,
                       wavog::BlockRegion* out, std::string* why) {
  const double block = grid.resolution * std::ldexp(1.0, grid.block_levels);
  std::int64_t b[4] = {0, 0, 0, 0};
  for (std::size_t i = 0; i < 4; ++i) {
    const double k = region[i] / block;
    if (!std::isfinite(k) || std::abs(k) > 1e12) {
      *why = "value " + fmt(region[i]) + " is not a finite coordinate";
      return false;
    }
    const double rounded = std::round(k);
    if (std::abs(k - rounded) > 1e-6) {
      *why = "value " + fmt(region[i]) + " is not a multiple of " + fmt(block) + " m";
      return false;
    }
    b[i] = static_cast<std::int64_t>(rounded);
  }
  if (!(b[0] < b[2] && b[1] < b[3])) {
    *why = "min must be below max on both axes";
    return false;
  }
  out->all = false;
  out->min_bx = b[0];
  out->min_by = b[1];
  out->max_bx = b[2];
  out->max_by = b[3];
  return true;
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
