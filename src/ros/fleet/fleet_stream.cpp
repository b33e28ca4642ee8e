// FleetStream (see fleet_stream.h).
#include "fleet_stream.h"

#include <boost/make_shared.hpp>
#include <utility>

#include "placed_scan.h"

namespace wavog_fleet {
namespace {

/// Messages roscpp queues per subscriber before dropping the oldest (the fleet node counts the
/// loss from PlacedScan.index gaps).
constexpr std::uint32_t kQueue = 2000;
/// Period (wall s) of the sweep for scans queued outside the scan path.
constexpr double kSweepPeriod = 0.05;
/// Wall s between the first subscriber's connection and the stream's start.
constexpr double kConnectGrace = 0.5;
/// Scans held before the stream starts (4 lasers x 40 Hz for 5 s).
constexpr std::size_t kMaxHeld = 800;

}  // namespace

FleetStream::FleetStream(ros::NodeHandle nh, std::string vehicle, std::string map_frame,
                         bool codes)
    : vehicle_(std::move(vehicle)), map_frame_(std::move(map_frame)), codes_(codes) {
  pub_ = nh.advertise<wavog_mapping::PlacedScan>("fleet_scans", kQueue);
  topic_ = pub_.getTopic();
  timer_ = nh.createWallTimer(ros::WallDuration(kSweepPeriod),
                              [this](const ros::WallTimerEvent&) { publishQueued(); });
}

wavog::ScanView FleetStream::streamView(const wavog::ScanView& view,
                                        const wavog::MapParams& params) {
  encoded_ = codes_ && codec_.encode(view, params);
  return encoded_ ? codec_.decodedView(view) : view;
}

void FleetStream::queue(const ros::Time& stamp, const std::string& input,
                        const wavog::Pose2& pose, const wavog::ScanView& view, bool compensated,
                        const wavog::Pose2& start, const wavog::Pose2& end) {
  auto m = boost::make_shared<wavog_mapping::PlacedScan>();
  std::lock_guard<std::mutex> lock(mutex_);
  fillPlacedScan(stamp, map_frame_, vehicle_, input, index_++, pose, view, compensated, start,
                 end, m.get(), encoded_ ? &codec_ : nullptr);
  queued_.push_back(std::move(m));
}

void FleetStream::publishQueued() {
  std::lock_guard<std::mutex> publishing(publish_mutex_);
  if (!started_) {
    const ros::WallTime now = ros::WallTime::now();
    if (pub_.getNumSubscribers() == 0) {
      first_subscriber_ = ros::WallTime();
    } else if (first_subscriber_.isZero()) {
      first_subscriber_ = now;
    }
    started_ = !first_subscriber_.isZero() && (now - first_subscriber_).toSec() >= kConnectGrace;
    if (!started_) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (queued_.size() > kMaxHeld) {
        queued_.erase(queued_.begin(), queued_.end() - static_cast<std::ptrdiff_t>(kMaxHeld));
      }
      return;
    }
  }
  std::vector<wavog_mapping::PlacedScan::Ptr> out;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    out.swap(queued_);
  }
  for (const auto& m : out) pub_.publish(m);
}

}  // namespace wavog_fleet
