// libFuzzer harness: the node's message-to-core path without a roscore, on arbitrary LaserScan
// fields and transforms: checkScan and checkScanTime (the drop decisions of onScan), the tf
// buffer fed with hostile transforms at the scan's first and last beam, placeScan (pose
// conversion, mirroring), placedView (motion compensation), the core's integrate, scanReach, and
// the publication sizing (layerBox at every scale with a hostile window and centre), then the
// read-out of what layerBox accepts and its OccupancyGrid message.
// The contract: nothing throws (placeScan never does; ROS time arithmetic on a scan that passed
// checkScanTime cannot), no undefined behaviour, and a layer layerBox accepts holds at most
// kMaxLayerCells cells.
#include <console_bridge/console.h>
#include <geometry_msgs/TransformStamped.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2/buffer_core.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "fuzz_support.h"
#include "wavog_mapping/core/motion_compensation.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/ros/conversions.h"
#include "wavog_mapping/ros/scan_placement.h"

namespace {

using wavog_fuzz::hostileDouble;
using wavog_fuzz::hostileNsec;
using wavog_fuzz::hostileRange;
using wavog_fuzz::hostileSec;

constexpr std::size_t kMaxBeams = 720;
/// Read-outs above this many cells are only sized, not filled (instrumented fill loops).
constexpr double kReadOutCells = 1 << 16;

const char* const kFrames[] = {"laser", "map", "", "/laser", "other"};

sensor_msgs::LaserScan decodeScan(FuzzedDataProvider* in) {
  sensor_msgs::LaserScan s;
  s.header.frame_id = kFrames[in->ConsumeIntegralInRange<std::size_t>(0, 4)];
  s.header.stamp.sec = hostileSec(in);
  s.header.stamp.nsec = hostileNsec(in);
  const auto f = [in](double lo, double hi) {
    return static_cast<float>(hostileDouble(in, lo, hi));
  };
  s.angle_min = f(-3.2, 3.2);
  s.angle_increment = f(-0.1, 0.1);
  const std::size_t n = in->ConsumeIntegralInRange<std::size_t>(0, kMaxBeams);
  // angle_max consistent with the beam count most of the time, so that checkScan passes.
  s.angle_max = in->ConsumeBool() ? static_cast<float>(static_cast<double>(s.angle_min) +
                                                       static_cast<double>(s.angle_increment) *
                                                           (static_cast<double>(n) - 1.0))
                                  : f(-3.2, 3.2);
  s.time_increment = in->ConsumeBool() ? f(-1e-3, 1e-3) : 1.0f / (75.0f * 360.0f);
  s.scan_time = f(0.0, 1.0);
  s.range_min = f(0.0, 1.0);
  s.range_max = f(0.0, 100.0);
  s.ranges.resize(n);
  for (float& r : s.ranges) r = hostileRange(in, 90.0f);
  return s;
}

geometry_msgs::TransformStamped decodeTransform(FuzzedDataProvider* in, const ros::Time& stamp) {
  geometry_msgs::TransformStamped t;
  t.header.frame_id = "map";
  t.child_frame_id = "laser";
  t.header.stamp = stamp;
  t.transform.translation.x = hostileDouble(in, -50.0, 50.0);
  t.transform.translation.y = hostileDouble(in, -50.0, 50.0);
  t.transform.translation.z = hostileDouble(in, -1.0, 1.0);
  if (in->ConsumeBool()) {  // a yaw, possibly upside down
    const double yaw = in->ConsumeFloatingPointInRange<double>(-3.2, 3.2);
    const bool flip = in->ConsumeBool();
    // flip: half a turn about the horizontal axis at yaw / 2 (z axis pointing down).
    t.transform.rotation.w = flip ? 0.0 : std::cos(yaw / 2);
    t.transform.rotation.z = flip ? 0.0 : std::sin(yaw / 2);
    t.transform.rotation.x = flip ? std::cos(yaw / 2) : 0.0;
    t.transform.rotation.y = flip ? std::sin(yaw / 2) : 0.0;
  } else {
    t.transform.rotation.x = hostileDouble(in, -1.0, 1.0);
    t.transform.rotation.y = hostileDouble(in, -1.0, 1.0);
    t.transform.rotation.z = hostileDouble(in, -1.0, 1.0);
    t.transform.rotation.w = hostileDouble(in, -1.0, 1.0);
  }
  return t;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool quiet = [] {
    console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);  // tf's refusals
    return true;
  }();
  (void)quiet;
  FuzzedDataProvider in(data, size);
  wavog::MapParams params = wavog::MapParams::defaultsFor(wavog::PolicyType::kForget);
  params.grid.resolution = in.ConsumeBool() ? 0.1 : 0.05;
  params.grid.block_levels = in.ConsumeIntegralInRange<int>(3, 6);
  params.sensor.max_range = in.ConsumeBool() ? 0.0 : in.ConsumeFloatingPointInRange<double>(0, 80);
  wavog::WaveletMap map(params);
  wavog_ros::PlacementOptions options;
  options.motion_compensation = in.ConsumeBool();
  const double tolerance = in.ConsumeFloatingPointInRange<double>(0.0, 1.0);

  const sensor_msgs::LaserScan scan = decodeScan(&in);
  tf2::BufferCore tf(ros::Duration(10.0));
  const int transforms = in.ConsumeIntegralInRange<int>(0, 3);
  for (int i = 0; i < transforms; ++i) {
    ros::Time stamp = scan.header.stamp;
    if (in.ConsumeBool()) {
      ros::Time shifted;
      if (wavog_ros::addSeconds(stamp, hostileDouble(&in, -0.1, 0.1), &shifted)) stamp = shifted;
    }
    // As onTf: a stamp the buffer's pruning cannot take is refused before it.
    if (!wavog_ros::tfStampUsable(stamp, 10.0)) continue;
    try {
      tf.setTransform(decodeTransform(&in, stamp), "fuzz", in.ConsumeBool());  // may refuse
    } catch (const std::exception& e) {
      WAVOG_FUZZ_CHECK(false, "setTransform threw after tfStampUsable: %s", e.what());
    }
  }
  const double window = in.ConsumeBool() ? 0.0 : hostileDouble(&in, 0.0, 50.0);
  const double cx = hostileDouble(&in, -50.0, 50.0), cy = hostileDouble(&in, -50.0, 50.0);

  // onScan: the time arithmetic of the node on the stamp against another stamp.
  ros::Time previous;  // fields set as deserialisation does: not normalised (nsec may pass 1e9)
  previous.sec = hostileSec(&in);
  previous.nsec = hostileNsec(&in);
  const double back = wavog_ros::secondsBetween(previous, scan.header.stamp);
  WAVOG_FUZZ_CHECK(std::isfinite(back), "secondsBetween not finite: %g", back);

  wavog_ros::DropReason reason{};
  if (!wavog_ros::checkScan(scan, &reason)) return 0;
  if (!wavog_ros::checkScanTime(scan, tolerance, &reason)) return 0;
  // What the tf filter and placeScan then compute may not throw.
  try {
    (void)(scan.header.stamp + ros::Duration(tolerance));
    (void)(scan.header.stamp + ros::Duration(wavog_ros::sweepSeconds(scan)));
  } catch (const std::exception& e) {
    WAVOG_FUZZ_CHECK(false, "time arithmetic threw after checkScanTime: %s", e.what());
  }
  wavog_ros::ScanPlacement placement;
  try {
    placement = wavog_ros::placeScan(tf, scan, options);
  } catch (const std::exception& e) {
    WAVOG_FUZZ_CHECK(false, "placeScan threw: %s", e.what());
  }
  if (!placement.placed()) return 0;

  wavog::MotionCompensator compensator;
  wavog::Pose2 pose;
  const wavog::ScanView view = placement.placedView(scan, &compensator, &pose);
  WAVOG_FUZZ_CHECK(view.count == scan.ranges.size(), "view of %zu beams for %zu", view.count,
                   scan.ranges.size());
  const wavog::IntegrateStats st = map.integrate(pose, view);
  if (st.status == wavog::ScanStatus::kOk) {
    (void)wavog::scanReach(view, params.sensor, params.grid.resolution);
  }

  // Publication sizing at every scale, then the read-out of what it accepts.
  for (int s = 0; s <= params.grid.block_levels; ++s) {
    wavog::CellBox box;
    const wavog_ros::LayerSize ls = wavog_ros::layerBox(map, s, window, cx, cy, &box);
    if (ls != wavog_ros::LayerSize::kOk) continue;
    const double cells = static_cast<double>(box.width()) * static_cast<double>(box.height());
    WAVOG_FUZZ_CHECK(!box.empty() && cells <= wavog_ros::kMaxLayerCells,
                     "layer of %g cells accepted", cells);
    if (cells > kReadOutCells) continue;  // harness speed, not a limit of the node
    const wavog::Raster r = map.exportScale(s, box, wavog::Aggregation::kMean);
    wavog::GridValues values;
    values.trinary = (s & 1) == 0;  // both kinds of values
    const auto msg = wavog_ros::toOccupancyGridMsg(r, values, "map", ros::Time(1, 0));
    WAVOG_FUZZ_CHECK(
        msg->data.size() == static_cast<std::size_t>(msg->info.width) * msg->info.height,
        "grid of %zu values for %u x %u", msg->data.size(), msg->info.width, msg->info.height);
    for (const std::int8_t v : msg->data) {
      WAVOG_FUZZ_CHECK(v == -1 || (values.trinary ? (v == 0 || v == 100) : (v >= 0 && v <= 100)),
                       "grid value %d (trinary %d)", static_cast<int>(v),
                       static_cast<int>(values.trinary));
    }
  }
  return 0;
}
