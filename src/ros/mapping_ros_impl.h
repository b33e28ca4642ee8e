// MappingRos::Impl: the state of the mapper and which lock guards what. Its methods are split by
// role: mapping_ros.cpp (construction: inputs, tf, publishers, services, reconfigure, timers),
// mapping_ros_scans.cpp (one scan, from the callback to the core call), mapping_ros_tf_wait.cpp
// (scans waiting for tf, released in the order received), mapping_ros_publish.cpp
// (timers: layers, map_updates, ~status), mapping_ros_diagnostics.cpp (/diagnostics),
// mapping_ros_services.cpp (~reset, ~clear_region, ~save_map, ~flush, dynamic_map),
// mapping_ros_flush.cpp (the end of the input: scans still waiting for tf, the last publication).
#ifndef WAVOG_MAPPING_SRC_ROS_MAPPING_ROS_IMPL_H_
#define WAVOG_MAPPING_SRC_ROS_MAPPING_ROS_IMPL_H_

#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/update_functions.h>
#include <nav_msgs/GetMap.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <std_srvs/Empty.h>
#include <std_srvs/Trigger.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>

#include <array>
#include <atomic>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "checked_subscription.h"
#include "input_status.h"
#include "map_publisher.h"
#include "reconfigure.h"
#include "tf_messages.h"
#include "wavog_mapping/ClearRegion.h"
#include "wavog_mapping/MapperStatus.h"
#include "wavog_mapping/MappingConfig.h"
#include "wavog_mapping/SaveMap.h"
#include "wavog_mapping/core/motion_compensation.h"
#include "wavog_mapping/core/scan_period.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/ros/config.h"
#include "wavog_mapping/ros/mapping_ros.h"
#include "wavog_mapping/ros/pose_check.h"
#include "wavog_mapping/ros/scan_placement.h"

namespace wavog_fleet {
class FleetStream;
class FleetReceiver;
class VehicleWindows;
}  // namespace wavog_fleet

namespace wavog_ros {

using ScanFilter = tf2_ros::MessageFilter<sensor_msgs::LaserScan>;

/// Seconds between two warnings of the same input and reason.
constexpr double kWarnPeriod = 5.0;
/// Wall seconds between the console warnings about an input nothing publishes (warnSilentInputs).
constexpr double kSilentInputPeriod = 10.0;
/// Wall seconds between two tries to place the scans pushed out of the tf filter (onRetryTimer).
constexpr double kRetryPeriod = 0.1;
/// Warning slots of an input (Input::last_warn) after one per drop reason.
enum WarningSlot : std::size_t {
  kOtherWarning = kNumDropReasons,  ///< time jumps and motion fallbacks
  kLostWarning,                     ///< scans lost before the node received them
  kBeamCountWarning,                ///< range count disagreeing with the angles
  kIntensitiesWarning,              ///< intensities of another length than ranges
  kNumWarningSlots
};

/// A scan between the tf filter and the map (Input::pending).
struct PendingScan {
  sensor_msgs::LaserScan::ConstPtr scan;
  bool placed = false;  ///< out of the filter: `placement` holds what tf said (or its failure)
  ScanPlacement placement;  ///< valid when `placed`
  /// Waits here for tf, outside the filter: pushed out of the full filter (more than queue_size
  /// scans waiting for tf), or passed by it before tf covered its sweep's end (motion
  /// compensation). Placed by releaseReadyLocked once tf covers its stamp + tf_tolerance and its
  /// sweep's end (Input::outside counts these).
  bool outside = false;
};

/// One LaserScan input: its subscription, its tf filter and its counters.
struct Input {
  InputConfig config;
  std::string topic;  ///< resolved name
  ros::Subscriber sub;
  std::unique_ptr<ScanFilter> filter;
  InputCounters c;  ///< guarded by Impl::mutex_
  /// Last warning per drop reason, then per WarningSlot.
  std::array<ros::WallTime, kNumWarningSlots> last_warn;
  double min_freq = 0.0;  ///< diagnostics bounds (the FrequencyStatus keeps pointers to them)
  double max_freq = 0.0;
  diagnostic_updater::FrequencyStatus* freq = nullptr;  ///< owned by Impl::freq_; may be null
  /// Lost scans at the last /diagnostics update (guarded by Impl::mutex_).
  mutable std::uint64_t lost_reported = 0;
  bool slash_warned = false;  ///< the leading-'/' warning was given (guarded by Impl::mutex_)
  wavog::ScanPeriod period;   ///< of this laser's scans, for forget_half_life (Impl::mutex_)
  PoseCheck poses;            ///< absurd poses from tf (Impl::mutex_)
  /// Scans handed to the tf filter and not yet integrated, dropped or flushed, in the order they
  /// were received; whoever removes a scan from here owns it. Guarded by Impl::mutex_. The filter
  /// hands scans on from several threads in any order; they are integrated from the front only,
  /// so in the order received, as wavog_offline does (issue 42). At most 2 x queue_size +
  /// subscriber_queue_size long: the filter holds at most queue_size; a scan it pushes out waits
  /// here (`outside`) only while tf connects its frame, and at most subscriber_queue_size of those;
  /// a scan that holds up more than queue_size placed ones is dropped (releaseReadyLocked).
  std::deque<PendingScan> pending;
  std::size_t outside = 0;  ///< entries of `pending` with `outside` set (Impl::mutex_)
};

struct MappingRos::Impl {
  Impl(const ros::NodeHandle& nh, const ros::NodeHandle& pnh, MapperRole role);
  ~Impl();

  // ---- construction (mapping_ros.cpp)
  /// Warns about each payload of the map file at `path` this configuration does not keep.
  void warnDroppedPayloads(const std::string& path) const;
  void subscribeTf();
  void addInput(const InputConfig& ic);
  void startReconfigure();
  void startTimers();
  /// Applies a reconfiguration, or returns every reason to refuse it (then nothing changes).
  std::vector<std::string> onReconfigure(const wavog_mapping::MappingConfig& rc);

  // ---- one scan (mapping_ros_scans.cpp), in the order a scan passes them
  /// `connection`: an opaque id of the connection the scan came through (SeqGapCounter).
  void onScan(Input* in, const sensor_msgs::LaserScan::ConstPtr& scan, std::uintptr_t connection);
  /// A scan refused before deserialisation (checked_subscription.h: an array longer than the
  /// message's bytes, or truncated): received, dropped as bad_length, warned; `partial.header`
  /// counts lost scans when it was read.
  void onRefusedScan(Input* in, const sensor_msgs::LaserScan& partial, const Refused& refused);
  /// Counts the scans missing before `scan` (header.seq gaps) and warns. Under mutex_.
  void countLostLocked(Input* in, const sensor_msgs::LaserScan& scan, std::uintptr_t connection);
  /// Counts and warns about a checked scan that is integrated all the same: a range count that
  /// disagrees with its angles, intensities of another length. Under mutex_.
  void countOddGeometryLocked(Input* in, const sensor_msgs::LaserScan& scan);
  void onTf(const tf2_msgs::TFMessage::ConstPtr& msg, bool is_static);
  void onFilterFailure(Input* in, const sensor_msgs::LaserScan::ConstPtr& scan,
                       tf2_ros::filter_failure_reasons::FilterFailureReason reason);
  void onTransformable(Input* in, const sensor_msgs::LaserScan::ConstPtr& scan);
  // ---- scans waiting for tf (mapping_ros_tf_wait.cpp)
  /// The entry of `scan` in in->pending; null if it is not there (flushed or already handled).
  PendingScan* findPendingLocked(Input* in, const sensor_msgs::LaserScan* scan);
  /// Integrates (or drops) the placed scans at the front of in->pending, in the order received,
  /// up to the first one still waiting for tf; a scan pushed out of the filter at the front is
  /// placed here once tf covers it. Returns how many left the queue.
  std::size_t releaseReadyLocked(Input* in);
  /// The drop message of a scan tf cannot place while more than queue_size later ones are placed.
  std::string laterScansPlacedText() const;
  /// Why the scan at the front of in->pending, waiting outside the filter and not yet placeable,
  /// must be dropped now (`reason` set), or empty: it goes on waiting for tf.
  std::string outsideDropLocked(Input* in, DropReason* reason);
  /// Wall timer (retry_timer_): places the scans pushed out of the filter that tf now covers,
  /// when no other scan of their input comes to do it (the end of a bag, tf in one late burst).
  void onRetryTimer(const ros::WallTimerEvent&);
  // ---- one scan, continued (mapping_ros_scans.cpp)
  /// A scan tf has placed (or failed to): dropped, or integrated with its placement.
  void integratePlacedScanLocked(Input* in, const sensor_msgs::LaserScan& scan,
                                 const ScanPlacement& placement);
  void integrateLocked(Input* in, const sensor_msgs::LaserScan& scan,
                       const ScanPlacement& placement);
  void dropLocked(Input* in, DropReason reason, const std::string& detail);
  void warnLocked(Input* in, std::size_t slot, const std::string& text);

  // ---- the fleet (mapping_ros_fleet.cpp, src/ros/fleet/)
  /// Mapper: the stream when fleet_stream is on. Fleet node: the vehicles' streams, and a tf
  /// buffer without subscriptions. Throws std::invalid_argument on a parameter the role refuses.
  void startFleet(MapperRole role);
  /// The fleet node's core call (the counters and the dirty region, as integrateLocked).
  wavog::IntegrateStats integratePlacedLocked(const wavog::Pose2& pose,
                                              const wavog::ScanView& view);

  // ---- what no callback, timer or service lets escape (mapping_ros_scans.cpp)
  /// Counts an exception caught in `where` (and, with an input, the scan as dropped), throttled
  /// ROS_ERROR. Takes the lock itself: call it with mutex_ released.
  void caught(const char* where, const char* what, Input* in);
  /// Runs f(), catching and counting (caught()) whatever it throws.
  template <typename F>
  void guarded(const char* where, Input* in, F&& f) {
    try {
      f();
    } catch (const std::exception& e) {
      caught(where, e.what(), in);
    } catch (...) {
      caught(where, "unknown exception", in);
    }
  }

  // ---- the end of the input (mapping_ros_flush.cpp)
  /// Input stopped for idle_timeout (wall time: a bag's clock stops with it): flush, publish.
  void onIdleTimer(const ros::WallTimerEvent&);
  /// Integrates every scan still waiting for tf with the latest transform of its frame (the tf
  /// buffer has nothing newer); returns how many were integrated.
  std::size_t flushPending();
  /// Something arrived (a scan or tf): the input is not idle.
  void noteActivity();

  // ---- publication and status (mapping_ros_publish.cpp)
  void onPublishTimer(const ros::WallTimerEvent&);
  /// The centre of publish_window and of the fallback window of a layer too large as a whole:
  /// base_frame in map_frame from tf (latest), else the sensor of the last scan, else (0, 0).
  /// False, with a throttled warning ending in `consequence`, only with publish_window and neither
  /// pose. Takes mutex_ itself: call it without.
  bool windowCentre(const char* consequence, double* cx, double* cy);
  /// Reads and publishes every layer and ~status now (timer, end of input, services).
  void publishAll();
  /// Publishes ~status alone (the end of the input when the map has not changed since).
  void publishStatus();
  void onUpdateTimer(const ros::WallTimerEvent&);
  wavog_mapping::MapperStatus::Ptr statusLocked(const ros::Time& now);

  // ---- /diagnostics (mapping_ros_diagnostics.cpp)
  void diagnoseInput(const Input* in, diagnostic_updater::DiagnosticStatusWrapper& stat);
  void diagnoseMapper(diagnostic_updater::DiagnosticStatusWrapper& stat);
  /// Wall timer (silent_timer_): inputs without a publisher that have received nothing, warned on
  /// the console with the LaserScan topics the master knows (a bag on /front_laser/scan against
  /// the default `scan`); stops once every input has received a scan.
  void warnSilentInputs();

  // ---- services (mapping_ros_services.cpp)
  void advertiseServices();  ///< each handler guarded: an exception is a failed answer, counted
  bool onReset(std_srvs::Empty::Request&, std_srvs::Empty::Response&);
  bool onClearRegion(wavog_mapping::ClearRegion::Request& req,
                     wavog_mapping::ClearRegion::Response& res);
  bool onSaveMap(wavog_mapping::SaveMap::Request& req, wavog_mapping::SaveMap::Response& res);
  bool onFlush(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res);
  /// The `map` layer as a publication now would carry it; false (logged, throttled) when it
  /// cannot: no observed cell yet, no window centre, or larger than kMaxLayerCells (counted in
  /// layers_refused).
  bool onDynamicMap(nav_msgs::GetMap::Response& res);

  ros::NodeHandle nh_, pnh_;
  Config config_;  ///< the run-time part changes only in onReconfigure(); guarded by mutex_
  PlacementOptions placement_;  ///< constant after construction

  // tf first: the filters (in inputs_) refer to the buffer and are destroyed before it.
  std::unique_ptr<tf2_ros::Buffer> buffer_;
  /// Our own /tf and /tf_static subscribers instead of tf2_ros::TransformListener: Debian's
  /// tf2_ros (0.7.6) MessageFilter::add() registers its transformable request before queueing the
  /// message, so a transform inserted by another thread in between notifies nobody and the scan
  /// waits in the filter forever (seen in fast bag playback: a few scans of 300 never processed).
  /// tf_mutex_ serialises tf insertion with MessageFilter::add() and buffer clearing.
  std::mutex tf_mutex_;
  ros::Subscriber tf_sub_, tf_static_sub_;

  /// The one lock: map_, compensator_, publisher_, every Input::c, the statistics and config_.
  /// Never held while publishing or while waiting on tf.
  std::mutex mutex_;
  wavog::WaveletMap map_;
  wavog::MotionCompensator compensator_;
  std::vector<std::unique_ptr<Input>> inputs_;
  ros::Time last_now_;  ///< clock at the last scan (backwards-jump check)
  std::uint64_t clock_jumps_ = 0;
  std::uint64_t exceptions_ = 0;      ///< caught by guarded()
  std::uint64_t layers_refused_ = 0;  ///< over kMaxLayerCells: not published, saved, served
  std::uint64_t tf_refused_ = 0;      ///< transforms the tf buffer could not take
  // Integration time over the current status period.
  double integrate_time_sum_ = 0.0;
  double integrate_time_max_ = 0.0;
  std::uint64_t integrate_count_ = 0;
  double last_mean_ = 0.0, last_max_ = 0.0;  ///< of the last finished period (diagnostics)
  double publish_time_ = 0.0;
  ros::Time last_status_time_;
  std::uint64_t tf_failures_reported_ = 0;  ///< tf failures at the last diagnostics update
  /// Steady-clock time (ns) of the last scan or tf message; read by the idle timer.
  std::atomic<std::int64_t> last_activity_ns_{0};
  /// The current idle period was handled (flushed and published); cleared by noteActivity().
  std::atomic<bool> idle_handled_{false};
  bool changed_since_publish_ = false;  ///< the map changed since the last publishAll()
  std::unique_ptr<MapPublisher> publisher_;

  ros::Publisher status_pub_;
  ros::ServiceServer reset_srv_, clear_srv_, save_srv_, flush_srv_, dynamic_map_srv_;
  ros::WallTimer publish_timer_, update_timer_, diag_timer_, idle_timer_, silent_timer_,
      retry_timer_;
  /// Serialises publications (publishAll, onUpdateTimer): taken before mutex_, never inside it.
  std::mutex publish_mutex_;
  bool windowed_warned_ = false;  ///< the fallback-window message was given (publish_mutex_)

  std::unique_ptr<diagnostic_updater::Updater> updater_;
  std::vector<std::unique_ptr<diagnostic_updater::FrequencyStatus>> freq_;

  std::unique_ptr<ReconfigureServer> reconfigure_;

  std::unique_ptr<wavog_fleet::FleetStream> fleet_stream_;      ///< null unless fleet_stream
  std::unique_ptr<wavog_fleet::FleetReceiver> fleet_;           ///< wavog_fleet only
  std::unique_ptr<wavog_fleet::VehicleWindows> fleet_windows_;  ///< wavog_fleet, fleet_window > 0
};

}  // namespace wavog_ros

#endif  // WAVOG_MAPPING_SRC_ROS_MAPPING_ROS_IMPL_H_
