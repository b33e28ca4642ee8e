// FleetStream: the mapper's side of a fleet (fleet_stream: true). With fleet_stream_format uint16
// the mapper integrates the view streamView() gives it (ranges encoded as 16-bit codes and decoded:
// range_codec.h), and the stream sends those codes (PlacedScan version 2); with float32 the view
// as it is (version 1). Each scan the core integrated is queued as a PlacedScan under the mapper's lock (queue(), cheap: a copy of the ranges) and
// published on fleet_scans outside it (publishQueued(): from the scan path once its lock is
// released, and from a 20 Hz wall timer for scans integrated elsewhere, e.g. at the end of a bag).
// The stream starts once a subscriber has been connected for kConnectGrace (so that a fleet node
// and its peers, which connect within moments of each other, all get the first scan); until then
// it holds at most kMaxHeld scans, the oldest dropped (a gap in PlacedScan.index).
// Thread-safe: its own small lock; never calls back into the mapper.
#ifndef WAVOG_MAPPING_SRC_ROS_FLEET_FLEET_STREAM_H_
#define WAVOG_MAPPING_SRC_ROS_FLEET_FLEET_STREAM_H_

#include <ros/ros.h>

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "range_codec.h"
#include "wavog_mapping/PlacedScan.h"
#include "wavog_mapping/core/params.h"
#include "wavog_mapping/core/types.h"

namespace wavog_fleet {

class FleetStream {
 public:
  /// Advertises `nh`/fleet_scans; `vehicle`: the id written into every message; `codes`: send
  /// 16-bit range codes (version 2), else float32 ranges (version 1).
  FleetStream(ros::NodeHandle nh, std::string vehicle, std::string map_frame, bool codes);

  /// The view the mapper integrates for `view` on a map of `params`, under the mapper's lock,
  /// before queue(): with codes, its ranges encoded and decoded (valid until the next call), else
  /// `view` itself (also for the rare scan no code fits: RangeCodec::encode()).
  wavog::ScanView streamView(const wavog::ScanView& view, const wavog::MapParams& params);
  /// One integrated scan (see fillPlacedScan), with the codes of the last streamView() if it
  /// encoded.
  void queue(const ros::Time& stamp, const std::string& input, const wavog::Pose2& pose,
             const wavog::ScanView& view, bool compensated, const wavog::Pose2& start,
             const wavog::Pose2& end);
  /// Publishes what queue() collected. Call without the mapper's lock.
  void publishQueued();

  const std::string& vehicle() const { return vehicle_; }
  const std::string& topic() const { return topic_; }

 private:
  std::string vehicle_, map_frame_, topic_;
  bool codes_;
  RangeCodec codec_;     ///< under the mapper's lock (streamView() and queue())
  bool encoded_ = false;  ///< the last streamView() encoded
  ros::Publisher pub_;
  ros::WallTimer timer_;
  std::mutex mutex_;  ///< queued_ and index_
  std::vector<wavog_mapping::PlacedScan::Ptr> queued_;
  std::uint64_t index_ = 0;
  std::mutex publish_mutex_;  ///< one publisher at a time, so that indices leave in order
  bool started_ = false;            ///< under publish_mutex_
  ros::WallTime first_subscriber_;  ///< under publish_mutex_; zero: none yet
};

}  // namespace wavog_fleet

#endif  // WAVOG_MAPPING_SRC_ROS_FLEET_FLEET_STREAM_H_
