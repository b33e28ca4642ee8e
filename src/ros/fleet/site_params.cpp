// readSiteParams, overlappingRegions (see site_params.h).
#include "site_params.h"

#include <ros/names.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "site_layers.h"

namespace wavog_fleet {
namespace {

using XmlRpc::XmlRpcValue;

std::string fmt(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

// What `v` is, for a message: its value if a number or string, else its type.
std::string show(XmlRpcValue v) {
  switch (v.getType()) {
    case XmlRpcValue::TypeInt:
      return std::to_string(static_cast<int>(v));
    case XmlRpcValue::TypeDouble:
      return fmt(static_cast<double>(v));
    case XmlRpcValue::TypeString:
      return "the string '" + static_cast<std::string>(v) + "'";
    case XmlRpcValue::TypeBoolean:
      return static_cast<bool>(v) ? "true" : "false";
    default:
      return "a value that is not a number";
  }
}

bool isNumber(const XmlRpcValue& v) {
  return v.getType() == XmlRpcValue::TypeInt || v.getType() == XmlRpcValue::TypeDouble;
}

double number(XmlRpcValue v) {
  return v.getType() == XmlRpcValue::TypeInt ? static_cast<double>(static_cast<int>(v))
                                             : static_cast<double>(v);
}

// A number parameter `key` of `root` (default `fallback` when absent) in [lo, hi] (lo excluded
// when `open_lo`); `range` says it in the message.
double readNumber(XmlRpcValue& root, const std::string& key, double fallback, double lo, double hi,
                  bool open_lo, const std::string& range) {
  if (!root.hasMember(key)) return fallback;
  XmlRpcValue& v = root[key];
  const std::string rule = "~" + key + " must be a number in " + range;
  if (!isNumber(v)) {
    throw std::invalid_argument(rule + ", not " + show(v) +
                                " (roslaunch passes nan, inf and other words as strings)");
  }
  const double x = number(v);
  if (!(std::isfinite(x) && (open_lo ? x > lo : x >= lo) && x <= hi)) {
    throw std::invalid_argument(rule + ", not " + fmt(x));
  }
  return x;
}

}  // namespace

SiteParams readSiteParams(const XmlRpc::XmlRpcValue& root_in) {
  XmlRpcValue root = root_in;  // operator[] is not const
  if (root.getType() != XmlRpcValue::TypeStruct) root = XmlRpcValue();
  const bool has = root.getType() == XmlRpcValue::TypeStruct;
  SiteParams p;
  const std::string shards_rule = "~shards must list the shards' namespaces (at least one)";
  if (!has || !root.hasMember("shards") || root["shards"].getType() != XmlRpcValue::TypeArray ||
      root["shards"].size() == 0) {
    throw std::invalid_argument(shards_rule);
  }
  for (int i = 0; i < root["shards"].size(); ++i) {
    XmlRpcValue& v = root["shards"][i];
    if (v.getType() != XmlRpcValue::TypeString) {
      throw std::invalid_argument(shards_rule + ": entry " + show(v) + " is not a namespace");
    }
    const std::string shard = v;
    std::string error;
    if (!ros::names::validate(shard, error)) {
      throw std::invalid_argument("~shards entry '" + shard + "' is not a ROS namespace: " + error);
    }
    for (const std::string& other : p.shards) {
      if (ros::names::clean(other) == ros::names::clean(shard)) {
        throw std::invalid_argument("~shards entry '" + shard +
                                    "' is listed twice: list each shard once");
      }
    }
    p.shards.push_back(shard);
  }
  const std::string scales_rule =
      "~scales must list the scales to assemble (each a whole number in [1, 12], published by "
      "every shard in publish_scales)";
  if (!root.hasMember("scales") || root["scales"].getType() != XmlRpcValue::TypeArray ||
      root["scales"].size() == 0) {
    throw std::invalid_argument(scales_rule);
  }
  for (int i = 0; i < root["scales"].size(); ++i) {
    XmlRpcValue& v = root["scales"][i];
    const double s = isNumber(v) ? number(v) : 0.0;  // a whole double (4.0) is fine, 3.5 is not
    if (!(s >= 1.0 && s <= 12.0 && s == std::floor(s))) {
      throw std::invalid_argument(scales_rule + ": entry " + show(v) + " is not");
    }
    if (std::find(p.scales.begin(), p.scales.end(), static_cast<int>(s)) != p.scales.end()) {
      throw std::invalid_argument(scales_rule + ": entry " + show(v) + " is listed twice");
    }
    p.scales.push_back(static_cast<int>(s));
  }
  p.rate = readNumber(root, "rate", 1.0, 0.0, 100.0, true, "(0, 100] Hz");
  const double limit = static_cast<double>(kMaxSiteCellsLimit);
  const double cells =
      readNumber(root, "max_cells", static_cast<double>(kDefaultMaxSiteCells), 1.0, limit, false,
                 "[1, " + std::to_string(kMaxSiteCellsLimit) + "] cells per site layer");
  if (cells != std::floor(cells)) {
    throw std::invalid_argument("~max_cells must be a whole number of cells, not " + fmt(cells));
  }
  p.max_cells = static_cast<std::uint64_t>(cells);
  return p;
}

bool readRegion(const XmlRpc::XmlRpcValue& value_in, std::vector<double>* region) {
  XmlRpcValue value = value_in;
  region->clear();
  if (value.getType() != XmlRpcValue::TypeArray) return false;
  if (value.size() == 0) return true;
  if (value.size() != 4) return false;
  for (int i = 0; i < 4; ++i) {
    if (!isNumber(value[i]) || !std::isfinite(number(value[i]))) return false;
    region->push_back(number(value[i]));
  }
  return (*region)[0] < (*region)[2] && (*region)[1] < (*region)[3];
}

std::vector<std::string> overlappingRegions(const std::vector<ShardRegion>& regions) {
  const auto show_region = [](const ShardRegion& r) {
    if (r.region.size() != 4) return r.shard + " (no fleet_region: everything)";
    return r.shard + " [" + fmt(r.region[0]) + ", " + fmt(r.region[1]) + ", " + fmt(r.region[2]) +
           ", " + fmt(r.region[3]) + "]";
  };
  std::vector<std::string> out;
  for (std::size_t a = 0; a < regions.size(); ++a) {
    for (std::size_t b = a + 1; b < regions.size(); ++b) {
      const std::vector<double>& ra = regions[a].region;
      const std::vector<double>& rb = regions[b].region;
      const bool overlap = ra.size() != 4 || rb.size() != 4 ||
                           (ra[0] < rb[2] && rb[0] < ra[2] && ra[1] < rb[3] && rb[1] < ra[3]);
      if (overlap) out.push_back(show_region(regions[a]) + " and " + show_region(regions[b]));
    }
  }
  return out;
}

}  // namespace wavog_fleet
