// FleetReceiver: the fleet node's inputs (wavog_fleet). One subscription per vehicle namespace
// (<ns>/fleet_scans, PlacedScan), each message checked (placed_scan.h), then held in a
// ReorderBuffer and handed to the map in stamp order: a scan waits fleet_reorder_wait (wall s),
// and beyond that until every stream still streaming (one per vehicle and input, StreamHorizon)
// has delivered a later stamp, at most fleet_reorder_max_wait; late, foreign and overflowing
// messages are counted by vehicle and reason, warned with a throttle; every stamp arithmetic is
// in double seconds (a hostile stamp cannot throw), and the per-vehicle index sequence
// (stream_index.h) counts lost messages exactly. A vehicle silent for fleet_stale_timeout is
// stale (diagnostics WARN, ~fleet_status); nothing waits for it, and its cells stay in the map
// like any region no longer observed.
// Locking: every member is guarded by the mapper's one mutex (passed in), and the integration
// callback runs under it.
#ifndef WAVOG_MAPPING_SRC_ROS_FLEET_FLEET_RECEIVER_H_
#define WAVOG_MAPPING_SRC_ROS_FLEET_FLEET_RECEIVER_H_

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "../checked_subscription.h"
#include "placed_scan.h"
#include "reorder_buffer.h"
#include "stream_horizon.h"
#include "stream_index.h"
#include "wavog_mapping/FleetStatus.h"
#include "wavog_mapping/PlacedScan.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/ros/config.h"

namespace wavog_fleet {

/// The core call of the mapper that owns the map: called under its lock.
using IntegrateFn = std::function<wavog::IntegrateStats(const wavog::Pose2&, const wavog::ScanView&)>;

class FleetReceiver {
 public:
  /// Subscribes to every vehicle of `ros.fleet_vehicles` (relative to `nh`); adds one diagnostics
  /// task per vehicle to `updater`; publishes ~fleet_status on `pnh`; `resolution`: the fleet
  /// map's cell size (m), for the pose limits. Throws std::invalid_argument if the list is empty.
  FleetReceiver(ros::NodeHandle nh, ros::NodeHandle pnh, const wavog_ros::RosParams& ros,
                double resolution, std::mutex* mutex, IntegrateFn integrate, diagnostic_updater::Updater* updater);
  ~FleetReceiver();

  /// The sensor position (map frame, m) of vehicle i's latest integrated scan, i in the order of
  /// fleet_vehicles; false when none yet (under the mapper's lock).
  bool latestPositionLocked(std::size_t i, double* x, double* y) const;
  /// Scans integrated, all vehicles (under the mapper's lock).
  std::uint64_t integratedLocked() const;
  /// The map layers were just read for publication at `now` (under the mapper's lock): every
  /// scan integrated since the previous publication is now in the published map; records its
  /// publish lag (VehicleStatus.publish_lag_max).
  void layersPublishedLocked(const ros::Time& now);
  /// Builds and publishes ~fleet_status (takes the lock itself).
  void publishStatus(const ros::Time& now);
  /// Integrates everything still buffered, in order (takes the lock itself); returns how many.
  std::size_t releaseAll();

 private:
  struct Vehicle;
  using Item = wavog_mapping::PlacedScan::ConstPtr;

  void onMessage(Vehicle* v, const ros::MessageEvent<const wavog_mapping::PlacedScan>& event);
  /// A message refused before deserialisation (checked_subscription.h): counted, warned.
  void onRefused(Vehicle* v, const wavog_mapping::PlacedScan& partial, const wavog_ros::Refused& r);
  void onReleaseTimer();
  void integrateLocked(Vehicle* v, const wavog_mapping::PlacedScan& m);
  void warnLocked(Vehicle* v, const std::string& text);
  void diagnose(const Vehicle* v, diagnostic_updater::DiagnosticStatusWrapper& stat);
  bool staleLocked(const Vehicle* v, const ros::WallTime& now) const;

  ros::NodeHandle nh_, pnh_;
  PlacedScanLimits limits_;
  double stale_timeout_;
  bool integrate_late_;
  double reorder_wait_;
  double reorder_max_wait_;
  std::mutex* mutex_;
  IntegrateFn integrate_;
  std::vector<std::unique_ptr<Vehicle>> vehicles_;
  std::vector<float> decoded_;  ///< a version-2 scan's ranges (under *mutex_)
  ReorderBuffer<Item> buffer_;
  StreamHorizon horizon_;  ///< how far every live stream has come (wall time of receipt)
  ros::Time integrated_stamp_;
  ros::Publisher status_pub_;
  ros::WallTimer release_timer_;
};

}  // namespace wavog_fleet

#endif  // WAVOG_MAPPING_SRC_ROS_FLEET_FLEET_RECEIVER_H_
