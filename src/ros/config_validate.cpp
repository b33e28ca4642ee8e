// The valid range of every parameter (see config.h): validate() names each bad key with its range,
// so bad configuration fails at start-up; fleetRegionBlocks() turns `fleet_region` into blocks.
#include "wavog_mapping/ros/config.h"

#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

namespace wavog_ros {
namespace {

std::string fmt(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

void check(bool ok, std::vector<std::string>* errors, const std::string& message) {
  if (!ok) errors->push_back(message);
}

}  // namespace

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
  // Each threshold on its side of P = 0.5 (the prior): the two never cross.
  const wavog::GridValues& gv = ros.grid_values;
  check(std::isfinite(gv.occupied_thresh) && gv.occupied_thresh >= 0.5 && gv.occupied_thresh <= 1.0,
        &e, "occupied_thresh (" + fmt(gv.occupied_thresh) + ") must be in [0.5, 1] (P(occ))");
  check(std::isfinite(gv.free_thresh) && gv.free_thresh >= 0.0 && gv.free_thresh <= 0.5, &e,
        "free_thresh (" + fmt(gv.free_thresh) + ") must be in [0, 0.5] (P(occ))");
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
  check(std::isfinite(ros.fleet_reorder_max_wait) &&
            ros.fleet_reorder_max_wait >= ros.fleet_reorder_wait &&
            ros.fleet_reorder_max_wait <= 600.0,
        &e,
        "fleet_reorder_max_wait (" + fmt(ros.fleet_reorder_max_wait) +
            ") must be in [fleet_reorder_wait (" + fmt(ros.fleet_reorder_wait) + "), 600] s");
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
  // A window of half-width w holds (2 w / resolution + 2)^2 cells at most (kMaxLayerCells). With
  // a bad resolution or block_levels (named by the map's own rules) the limits that depend on
  // them are not checked: they would add bogus errors.
  const bool grid_ok = std::isfinite(map.grid.resolution) && map.grid.resolution > 0.0 &&
                       map.grid.block_levels >= 2 && map.grid.block_levels <= 12;
  const double max_window = 0.5 * (4096.0 - 2.0) * map.grid.resolution;  // 4096^2 = 2^24 cells
  check(std::isfinite(ros.fleet_window) && ros.fleet_window >= 0.0 &&
            (!grid_ok || ros.fleet_window <= max_window),
        &e,
        "fleet_window (" + fmt(ros.fleet_window) + ") must be in [0, " +
            (grid_ok ? fmt(max_window) : "2047 x resolution") +
            "] m (0: off; the window must hold at most 2^24 cells)");
  if (!ros.fleet_region.empty() && grid_ok) {
    std::string why;
    wavog::BlockRegion r;
    if (ros.fleet_region.size() != 4) {
      why = "it has " + std::to_string(ros.fleet_region.size()) + " values";
    } else {
      fleetRegionBlocks(ros.fleet_region, map.grid, &r, &why);
    }
    const double extent = std::ldexp(map.grid.resolution, 30);
    check(why.empty(), &e,
          "fleet_region must be [] (everything) or [min_x, min_y, max_x, max_y] in m, min < max, "
          "each a multiple of the block size (resolution x 2^block_levels = " +
              fmt(map.grid.resolution * std::ldexp(1.0, map.grid.block_levels)) +
              " m) within the map's extent (+-" + fmt(extent) + " m): " + why);
  }
  return e;
}

std::string duplicateInputs(const std::vector<InputConfig>& inputs,
                            const std::function<std::string(const std::string&)>& resolve) {
  std::vector<std::string> resolved;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    resolved.push_back(resolve(inputs[i].topic));
    for (std::size_t j = 0; j < i; ++j) {
      if (resolved[j] != resolved[i]) continue;
      return "inputs[" + std::to_string(j) + "].topic ('" + inputs[j].topic + "') and inputs[" +
             std::to_string(i) + "].topic ('" + inputs[i].topic + "') are one topic, " +
             resolved[i] +
             ", in this namespace: every scan would be integrated twice; list each topic once in "
             "inputs";
    }
  }
  return "";
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
    // The core's extent: finest cell indices within +-2^30 (MapParams::validate checks the
    // blocks again, under its own name).
    const double limit = std::ldexp(1.0, 30 - grid.block_levels);
    if (std::abs(rounded) > limit) {
      *why = "value " + fmt(region[i]) + " is beyond the map's extent (+-" +
             fmt(std::ldexp(grid.resolution, 30)) + " m: 2^30 cells of resolution)";
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

}  // namespace wavog_ros
