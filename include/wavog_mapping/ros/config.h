// The one parameter loader of the package: the nodelet, the node and the offline tools all read
// their configuration through configFromXmlRpc(), from the ROS parameter server (loadConfig) or
// from a YAML file (loadConfigFile). Units: metres, seconds, hertz, log-odds. Thread-safety: the
// functions are reentrant; Config is a plain value.
#ifndef WAVOG_MAPPING_ROS_CONFIG_H_
#define WAVOG_MAPPING_ROS_CONFIG_H_

#include <ros/node_handle.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <functional>
#include <string>
#include <vector>

#include "wavog_mapping/core/params.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog_ros {

/// Most LaserScan inputs one mapper accepts.
constexpr int kMaxInputs = 4;

/// One LaserScan input.
struct InputConfig {
  /// Topic name, resolved in the node's namespace (relative names are remappable).
  std::string topic;
  /// Expected publication rate (Hz) for the diagnostics, in [0, 1000]; 0 disables the rate check.
  double expected_rate = 0.0;
};

/// Parameters of the ROS layer (the core's are in wavog::MapParams).
struct RosParams {
  /// Fixed frame of the map and of the published grids.
  std::string map_frame = "map";
  /// Robot frame; the centre of publish_window.
  std::string base_frame = "base_link";
  /// 1 to 4 LaserScan inputs.
  std::vector<InputConfig> inputs = {{"scan", 0.0}};
  /// Rate (Hz) of the full publication of every layer and of the status, in (0, 100].
  double publish_rate = 1.0;
  /// Scales s published as map_scale_<s> (cells 2^s times the resolution), each in
  /// [1, block_levels], distinct; may be empty.
  std::vector<int> publish_scales = {2, 3, 4};
  /// How a coarse cell summarises its finest cells: max (a coarse cell holding an occupied finest
  /// cell is occupied: what planners need) or mean (the Haar average).
  wavog::Aggregation scale_aggregation = wavog::Aggregation::kMax;
  /// Values of map, map_scale_<s>, map_updates, dynamic_map, the fleet windows and the saved
  /// map_server images (keys map_values: trinary | graded, occupied_thresh, free_thresh): trinary
  /// 0 / 100 / -1 by default, as map_server, amcl and costmap_2d read them.
  wavog::GridValues grid_values;
  /// Half-width (m) of the square around base_frame that is published, >= 0; 0: the whole map.
  double publish_window = 0.0;
  /// Rate (Hz) of map_updates (changed rectangle of the finest layer), in [0, 100]; 0: off.
  double update_rate = 0.0;
  /// A scan waits in the tf2 MessageFilter until tf is known up to stamp + this (s), in [0, 1].
  /// Motion compensation needs it >= the sweep duration (LMS-291: 13-27 ms).
  double tf_tolerance = 0.03;
  /// Length (s) of the tf buffer, in [1, 3600]; scans older than this cannot be placed.
  double tf_cache_time = 30.0;
  /// Scans per input waiting for tf in the MessageFilter, in [1, 1000].
  int queue_size = 20;
  /// Scans per input roscpp holds between the socket and the node's callback, in [1, 100000].
  /// roscpp silently drops the oldest when it is full (the node is slower than the input); the
  /// node counts those from gaps in header.seq (InputStatus::lost). /tf and /tf_static get
  /// queues as deep (at least 100), so queued scans find their tf after a stall.
  int subscriber_queue_size = 1000;
  /// Place each beam with the sensor pose interpolated over the sweep (needs time_increment).
  bool motion_compensation = true;
  /// Fastest plausible laser (m/s), in (0, 1000]: a scan whose pose from tf implies a faster
  /// move (a corrupt odometry sample) is refused as absurd_pose (pose_check.h).
  double max_sensor_speed = 50.0;
  /// Native map file loaded at start-up; empty: start with an empty map.
  std::string map_file;
  /// Directory ~save_map writes below (absolute, no '..'); relative paths resolve under it.
  /// Empty: the ROS home ($ROS_HOME, else ~/.ros).
  std::string map_dir;
  /// Relative tolerance of the diagnostics' rate check, in [0, 1).
  double rate_tolerance = 0.5;
  /// Wall time (s) without any scan or tf after which the input counts as stopped (the end of a
  /// bag): scans still waiting for tf are integrated with the latest tf and every layer is
  /// published once more; in [0, 3600], 0: never.
  double idle_timeout = 2.0;

  // ---- The fleet (issue 30; src/ros/fleet/) ----
  /// Mapper: publish every scan it integrates, placed in map_frame, on fleet_scans
  /// (wavog_mapping/PlacedScan) for a fleet node. Off: no publisher, no cost.
  bool fleet_stream = false;
  /// Mapper: how the stream carries ranges: "uint16" (PlacedScan version 2: 16-bit codes of 1 mm,
  /// which the mapper integrates decoded, so that its map and the fleet's agree exactly) or
  /// "float32" (version 1: the ranges as read). A fleet node reads both.
  std::string fleet_stream_format = "uint16";
  /// Mapper: the vehicle id in the stream; empty: the node's namespace.
  std::string vehicle_id;
  /// Fleet node: the vehicles' namespaces (1 to kMaxFleetVehicles); it subscribes to
  /// <namespace>/fleet_scans. Mappers ignore it.
  std::vector<std::string> fleet_vehicles;
  /// Fleet node: how long (wall s) a scan waits in the reorder buffer for older scans of other
  /// vehicles (and of vehicles not yet streaming) before it is integrated, in [0, 10]; after
  /// that it waits on while a stream still streaming has not delivered a later stamp.
  double fleet_reorder_wait = 0.3;
  /// Fleet node: the longest (wall s) a scan waits for a stream that still streams but lags, in
  /// [fleet_reorder_wait, 600]; fleet_reorder_wait: release by arrival time only.
  double fleet_reorder_max_wait = 10.0;
  /// Fleet node: wall s without a message after which a vehicle is stale, in (0, 3600].
  double fleet_stale_timeout = 2.0;
  /// Fleet node: a scan older than the newest integrated one is integrated anyway (true) or
  /// dropped (false); counted either way.
  bool fleet_integrate_late = true;
  /// Fleet node: most scans in the reorder buffer, in [1, 1000000]; beyond, refused (counted).
  int fleet_max_buffered = 20000;
  /// Fleet node: a scan stamped farther than this (s) from the fleet node's clock (sim time
  /// aware) is refused (dropped_bad_stamp), in (0, 86400]: one far-future stamp would otherwise
  /// make every later scan late. Covers clock skew, the mappers' tf wait and the stream's delay.
  double fleet_max_stamp_offset = 60.0;
  /// Fleet node: the region this node (a region shard) maps, [min_x, min_y, max_x, max_y] (m, map
  /// frame), each a multiple of the block size (resolution x 2^block_levels), min < max; it
  /// integrates every vehicle's scans into the blocks of this rectangle only (MapParams::region).
  /// Empty: everything (one fleet node for the site).
  std::vector<double> fleet_region;
  /// Fleet node: half-width (m) of the square around each vehicle's latest streamed position in
  /// which it publishes its finest layer back to the vehicle (<ns>/fleet_map, _updates); 0: off.
  /// At most the half-width whose window holds kMaxLayerCells cells.
  double fleet_window = 0.0;
};

/// Most vehicles one fleet node follows.
constexpr int kMaxFleetVehicles = 64;

/// Everything the mapper reads.
struct Config {
  wavog::MapParams map;
  RosParams ros;
};

/// Every top-level key the loader knows, in documentation order.
const std::vector<std::string>& knownKeys();

/// The one loader. Starts from MapParams::defaultsFor(policy) (policy from `root`, default
/// "forget") and RosParams{}, overrides with the keys of `root` (an XmlRpc struct; an invalid
/// value of any other type is treated as empty), then validates. Keys it does not know are
/// appended to *unknown_keys (if not null) and otherwise ignored. Throws std::invalid_argument
/// whose message names each bad parameter, its value and its valid range.
Config configFromXmlRpc(XmlRpc::XmlRpcValue& root, std::vector<std::string>* unknown_keys);

/// Reads the private namespace of `pnh` as one struct and calls configFromXmlRpc. The key
/// "scales", which the dynamic_reconfigure server writes there, is not reported as unknown.
Config loadConfig(const ros::NodeHandle& pnh, std::vector<std::string>* unknown_keys);

/// Parses a YAML file (a map of the keys above) and calls configFromXmlRpc. Throws
/// std::invalid_argument (also for an unreadable or malformed file, naming it).
Config loadConfigFile(const std::string& yaml_path, std::vector<std::string>* unknown_keys);

/// Converts YAML text to XmlRpc (maps, sequences, bool, int, double, string). Throws
/// std::invalid_argument on malformed YAML.
XmlRpc::XmlRpcValue yamlToXmlRpc(const std::string& yaml_text);

/// Aggregation <-> configuration name ("mean", "max").
const char* toString(wavog::Aggregation aggregation);
bool fromString(const std::string& name, wavog::Aggregation* aggregation);

/// fleet_region (m) as the blocks of a map of `grid` (`region` must hold 4 values): false, with
/// *why, when they are not finite, min < max, multiples of the block size and within the map's
/// extent (finest cell indices within +-2^30, as MapParams::region).
bool fleetRegionBlocks(const std::vector<double>& region, const wavog::GridParams& grid,
                       wavog::BlockRegion* out, std::string* why);

/// Every violation of the ROS parameters (given the core parameters), one line each.
std::vector<std::string> validate(const RosParams& ros, const wavog::MapParams& map);

/// Two inputs naming one topic once resolved by `resolve` (the node handle's resolveName: its
/// namespace and remappings; `scan` and `/scan` in the root namespace): the error naming
/// `inputs`, empty when every input is a topic of its own.
std::string duplicateInputs(const std::vector<InputConfig>& inputs,
                            const std::function<std::string(const std::string&)>& resolve);

}  // namespace wavog_ros

#endif  // WAVOG_MAPPING_ROS_CONFIG_H_
