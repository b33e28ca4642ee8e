// Message <-> core conversions (see conversions.h).
#include "wavog_mapping/ros/conversions.h"

#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2/LinearMath/Matrix3x3.h>
#include <tf2/LinearMath/Quaternion.h>

#include <algorithm>
#include <boost/make_shared.hpp>
#include <cmath>
#include <sstream>
#include <vector>

#include "wavog_mapping/core/limits.h"

namespace wavog_ros {
namespace {

/// Cells of a box, in double (no overflow).
double cells(const wavog::CellBox& b) {
  return b.empty() ? 0.0 : static_cast<double>(b.width()) * static_cast<double>(b.height());
}

/// [lo, hi] clipped to [clip_lo, clip_hi]; false when empty or not finite.
bool clip(double clip_lo, double clip_hi, double* lo, double* hi) {
  *lo = std::max(*lo, clip_lo);
  *hi = std::min(*hi, clip_hi);
  return std::isfinite(*lo) && std::isfinite(*hi) && *lo <= *hi;
}

}  // namespace

const char* toString(DropReason reason) {
  // In DropReason order.
  static constexpr const char* kNames[kNumDropReasons] = {
      "empty",       "bad_angles",    "bad_frame",    "tf_unavailable",
      "tf_too_old",  "no_valid_beam", "bad_geometry", "out_of_extent",
      "absurd_pose", "bad_time",      "exception",    "bad_length"};
  const auto i = static_cast<std::size_t>(reason);
  return i < kNumDropReasons ? kNames[i] : "unknown";
}

bool stripFrameSlash(std::string* frame_id) {
  if (frame_id->empty() || (*frame_id)[0] != '/') return false;
  frame_id->erase(0, 1);
  return true;
}

std::string frameSlashWarning(const std::string& frame_id) {
  return "frame_id '" + frame_id + "' has a leading '/' (tf1 style), which tf2 refuses: using '" +
         frame_id.substr(1) + "' for this input (warned once)";
}

bool checkScan(const sensor_msgs::LaserScan& scan, DropReason* reason) {
  const std::string& frame = scan.header.frame_id;
  if (frame.empty() || frame[0] == '/') {
    *reason = DropReason::kBadFrame;
    return false;
  }
  const double inc = scan.angle_increment;
  if (!std::isfinite(inc) || inc == 0.0 || !std::isfinite(scan.angle_min)) {
    *reason = DropReason::kBadAngles;
    return false;
  }
  if (scan.ranges.empty()) {
    *reason = DropReason::kEmpty;
    return false;
  }
  return true;
}

double impliedBeams(const sensor_msgs::LaserScan& scan) {
  return (static_cast<double>(scan.angle_max) - scan.angle_min) / scan.angle_increment + 1.0;
}

bool beamCountMismatch(const sensor_msgs::LaserScan& scan) {
  // Negated: a NaN (angle_max not finite) is a mismatch too.
  return !(std::abs(impliedBeams(scan) - static_cast<double>(scan.ranges.size())) <= 1.01);
}

bool intensitiesMismatch(const sensor_msgs::LaserScan& scan) {
  return !scan.intensities.empty() && scan.intensities.size() != scan.ranges.size();
}

double secondsBetween(const ros::Time& a, const ros::Time& b) {
  return (static_cast<double>(a.sec) - static_cast<double>(b.sec)) +
         (static_cast<double>(a.nsec) - static_cast<double>(b.nsec)) * 1e-9;
}

bool addSeconds(const ros::Time& t, double seconds, ros::Time* out) {
  if (!std::isfinite(seconds)) return false;
  const double sum = t.toSec() + seconds;
  // 2^32 - 1 s: one second short of the end of the range, so that rounding cannot reach it.
  constexpr double kLast = 4294967295.0 - 1.0;
  if (!(sum >= 0.0 && sum < kLast)) return false;
  // Both now fit: the arithmetic of ros::Time cannot throw (|seconds| < 2^32 as well).
  if (std::abs(seconds) >= 2147483647.0) {
    out->fromSec(sum);  // a Duration of this length would not fit; the sum does
  } else {
    *out = t + ros::Duration(seconds);
  }
  return true;
}

bool tfStampUsable(const ros::Time& stamp, double cache_time) {
  ros::Time ignored;
  return addSeconds(stamp, std::max(0.0, cache_time), &ignored);
}

double sweepSeconds(const sensor_msgs::LaserScan& scan) {
  if (scan.ranges.size() < 2) return 0.0;
  return static_cast<double>(scan.time_increment) * static_cast<double>(scan.ranges.size() - 1);
}

bool checkScanTime(const sensor_msgs::LaserScan& scan, double tolerance, DropReason* reason) {
  const double sweep = sweepSeconds(scan);
  ros::Time ignored;
  if (!std::isfinite(scan.time_increment) || !(std::abs(sweep) <= kMaxSweepSeconds) ||
      !addSeconds(scan.header.stamp, std::max(0.0, tolerance), &ignored) ||
      !addSeconds(scan.header.stamp, sweep, &ignored) ||
      !addSeconds(scan.header.stamp, sweep + std::max(0.0, tolerance), &ignored)) {
    *reason = DropReason::kBadTime;
    return false;
  }
  return true;
}

wavog::ScanView toScanView(const sensor_msgs::LaserScan& scan) {
  wavog::ScanView v;
  v.ranges = scan.ranges.data();
  v.count = scan.ranges.size();
  v.angle_min = scan.angle_min;
  v.angle_increment = scan.angle_increment;
  v.range_min = scan.range_min;
  v.range_max = scan.range_max;
  const double turn = 2.0 * M_PI;
  const double fov = std::abs(v.angle_increment) * static_cast<double>(v.count);
  if (fov > turn && fov <= turn * (1.0 + kFullTurnSlack)) {
    v.angle_increment = std::copysign(turn / static_cast<double>(v.count), v.angle_increment);
  }
  return v;
}

std::string geometryRefusal(const wavog::ScanView& v) {
  // The checks of the core (prepared_scan.cpp, checkScan) in its order, with limits.h's values.
  std::ostringstream s;
  const double beams = static_cast<double>(v.count);
  if (!(std::abs(v.angle_min) <= wavog::kMaxAbsAngleMin)) {
    s << "|angle_min| " << v.angle_min << " rad beyond " << wavog::kMaxAbsAngleMin << " rad";
  } else if (!std::isfinite(v.angle_increment) ||
             !(std::abs(v.angle_increment) >= wavog::kMinAbsAngleIncrement)) {
    s << "|angle_increment| " << v.angle_increment << " rad below " << wavog::kMinAbsAngleIncrement
      << " rad";
  } else if (!std::isfinite(v.range_min) || v.range_min < 0.0) {
    s << "range_min " << v.range_min << " m is negative or not finite";
  } else if (!(v.range_max > v.range_min)) {
    s << "range_max " << v.range_max << " m is not above range_min " << v.range_min << " m";
  } else if (v.count > wavog::kMaxBeams) {
    s << v.count << " beams, more than " << wavog::kMaxBeams;
  } else if (std::abs(v.angle_increment) * beams > 2.0 * M_PI + 1e-6) {
    s << "field of view " << v.count << " beams x " << std::abs(v.angle_increment)
      << " rad = " << std::abs(v.angle_increment) * beams << " rad beyond 2 pi";
  } else {
    s << "a geometry limit of the core (limits.h)";
  }
  return s.str();
}

wavog::Pose2 toPose2(const geometry_msgs::Transform& transform, bool* mirrored) {
  const tf2::Quaternion q(transform.rotation.x, transform.rotation.y, transform.rotation.z,
                          transform.rotation.w);
  const tf2::Matrix3x3 r(q);
  wavog::Pose2 pose;
  pose.x = transform.translation.x;
  pose.y = transform.translation.y;
  // Heading of the sensor's x axis projected on the map plane.
  pose.theta = std::atan2(r[1][0], r[0][0]);
  *mirrored = r[2][2] < 0.0;
  return pose;
}

void mirrorView(wavog::ScanView* view) {
  view->angle_min = -view->angle_min;
  view->angle_increment = -view->angle_increment;
}

std::string coreRefusal(const wavog::IntegrateStats& st, const wavog::ScanView& view,
                        const wavog::Pose2& pose, const wavog::MapParams& params) {
  std::ostringstream s;
  s << "refused by the core (" << wavog::toString(st.status) << "): ";
  switch (st.status) {
    case wavog::ScanStatus::kEmpty:
      s << "no beams";
      break;
    case wavog::ScanStatus::kNoValidBeam:
      s << "nothing to integrate: of " << view.count << " beams, " << st.beams_invalid
        << " invalid (NaN, -inf, <= 0 or below range_min " << view.range_min << " m), "
        << st.beams_no_return << " no return (+inf or >= range_max " << view.range_max
        << " m), of which " << st.beams_beyond_limit << " beyond the hard range limit of "
        << wavog::hardRangeLimit(params, view.count, view.angle_increment) << " m (limits.h, for "
        << view.count << " beams at resolution " << params.grid.resolution << " m and band_width "
        << params.sensor.band_width << " m)";
      break;
    case wavog::ScanStatus::kOutOfExtent:
      s << "the laser at (" << pose.x << ", " << pose.y << ") m plus its reach leaves the "
        << "representable extent of +-"
        << static_cast<double>(wavog::kCellIndexLimit) * params.grid.resolution
        << " m (2^30 cells)";
      break;
    case wavog::ScanStatus::kBadPose:
      s << "the laser's pose (" << pose.x << ", " << pose.y << ", " << pose.theta
        << ") is not finite";
      break;
    default:
      s << geometryRefusal(view);
  }
  return s.str();
}

LayerSize layerBox(const wavog::WaveletMap& map, int scale, double window, double cx, double cy,
                   wavog::CellBox* box) {
  wavog::CellBox b;
  if (!map.bounds(scale, &b) || b.empty()) return LayerSize::kEmpty;
  if (window > 0.0) {
    const double cell = std::ldexp(map.resolution(), scale);
    const double bx0 = static_cast<double>(b.min_x) * cell,
                 bx1 = static_cast<double>(b.max_x) * cell;
    const double by0 = static_cast<double>(b.min_y) * cell,
                 by1 = static_cast<double>(b.max_y) * cell;
    double x0 = cx - window, x1 = cx + window, y0 = cy - window, y1 = cy + window;
    if (!clip(bx0 - window, bx1 + window, &x0, &x1) ||
        !clip(by0 - window, by1 + window, &y0, &y1)) {
      return LayerSize::kEmpty;
    }
    if ((x1 - x0) / cell * ((y1 - y0) / cell) > kMaxLayerCells &&
        (!clip(bx0, bx1, &x0, &x1) || !clip(by0, by1, &y0, &y1))) {
      return LayerSize::kEmpty;
    }
    b = map.boxAround(x0, y0, x1, y1, scale);
  }
  *box = b;
  if (b.empty()) return LayerSize::kEmpty;
  return cells(b) > kMaxLayerCells ? LayerSize::kTooLarge : LayerSize::kOk;
}

namespace {
// The grid message of a raster of either kind, its cells `data`.
template <typename R>
nav_msgs::OccupancyGrid::Ptr gridMsg(const R& raster, std::vector<std::int8_t> data,
                                     const std::string& frame, const ros::Time& stamp) {
  auto msg = boost::make_shared<nav_msgs::OccupancyGrid>();
  msg->header.frame_id = frame;
  msg->header.stamp = stamp;
  msg->info.map_load_time = stamp;
  msg->info.resolution = static_cast<float>(raster.cell_size);
  msg->info.width = static_cast<std::uint32_t>(std::max<std::int64_t>(0, raster.box.width()));
  msg->info.height = static_cast<std::uint32_t>(std::max<std::int64_t>(0, raster.box.height()));
  msg->info.origin.position.x = raster.originX();
  msg->info.origin.position.y = raster.originY();
  msg->info.origin.orientation.w = 1.0;
  msg->data = std::move(data);
  return msg;
}
}  // namespace

nav_msgs::OccupancyGrid::Ptr toOccupancyGridMsg(const wavog::Raster& raster,
                                                const wavog::GridValues& values,
                                                const std::string& frame, const ros::Time& stamp) {
  return gridMsg(raster, wavog::toOccupancyGrid(raster, values), frame, stamp);
}

nav_msgs::OccupancyGrid::Ptr toOccupancyGridMsg(const wavog::ReflectionRaster& raster,
                                                const std::string& frame, const ros::Time& stamp) {
  return gridMsg(raster, wavog::toOccupancyGrid(raster), frame, stamp);
}

void ndtEllipse(double cov_xx, double cov_xy, double cov_yy, double* major, double* minor,
                double* yaw) {
  const wavog::NdtAxes axes = wavog::principalAxes(cov_xx, cov_xy, cov_yy);
  *major = 4.0 * axes.sigma_major;  // 2-sigma diameters
  *minor = 4.0 * axes.sigma_minor;
  *yaw = axes.yaw;
}

visualization_msgs::MarkerArray::Ptr toNdtMarkers(const wavog::NdtLayer& layer,
                                                  const std::string& frame,
                                                  const ros::Time& stamp) {
  auto msg = boost::make_shared<visualization_msgs::MarkerArray>();
  msg->markers.resize(layer.cells.size() + 1);
  const std::string ns = "ndt_scale_" + std::to_string(layer.scale);
  visualization_msgs::Marker& clear = msg->markers[0];
  clear.header.frame_id = frame;
  clear.header.stamp = stamp;
  clear.ns = ns;
  clear.action = visualization_msgs::Marker::DELETEALL;
  const double min_axis = kNdtMinAxisCells * layer.cell_size;
  for (std::size_t i = 0; i < layer.cells.size(); ++i) {
    const wavog::NdtCell& c = layer.cells[i];
    visualization_msgs::Marker& m = msg->markers[i + 1];
    m.header = clear.header;
    m.ns = ns;
    m.id = static_cast<std::int32_t>(i + 1);
    m.type = visualization_msgs::Marker::CYLINDER;
    m.action = visualization_msgs::Marker::ADD;
    double major = 0.0, minor = 0.0, yaw = 0.0;
    ndtEllipse(c.cov_xx, c.cov_xy, c.cov_yy, &major, &minor, &yaw);
    m.pose.position.x = c.mean_x;
    m.pose.position.y = c.mean_y;
    m.pose.position.z = kNdtMarkerThickness;  // just above the grids (z = 0)
    m.pose.orientation.z = std::sin(0.5 * yaw);
    m.pose.orientation.w = std::cos(0.5 * yaw);
    m.scale.x = std::max(major, min_axis);
    m.scale.y = std::max(minor, min_axis);
    m.scale.z = kNdtMarkerThickness;
    const double p = wavog::probabilityFromLogOdds(c.log_odds);
    m.color.r = static_cast<float>(p);
    m.color.g = 0.0f;
    m.color.b = static_cast<float>(1.0 - p);
    m.color.a = 0.8f;
  }
  return msg;
}

sensor_msgs::PointCloud2::Ptr toNdtCloud(const wavog::NdtLayer& layer, const std::string& frame,
                                         const ros::Time& stamp) {
  auto msg = boost::make_shared<sensor_msgs::PointCloud2>();
  msg->header.frame_id = frame;
  msg->header.stamp = stamp;
  msg->height = 1;  // unorganised: resize() then sets the width
  sensor_msgs::PointCloud2Modifier modifier(*msg);
  using sensor_msgs::PointField;
  // z (0: the map plane) is not NDT data: rviz draws, and PCL reads, only clouds with x, y and z.
  modifier.setPointCloud2Fields(8, "x", 1, PointField::FLOAT32, "y", 1, PointField::FLOAT32, "z", 1,
                                PointField::FLOAT32, "cov_xx", 1, PointField::FLOAT32, "cov_xy", 1,
                                PointField::FLOAT32, "cov_yy", 1, PointField::FLOAT32, "weight", 1,
                                PointField::FLOAT32, "occupancy", 1, PointField::FLOAT32);
  modifier.resize(layer.cells.size());
  msg->is_dense = true;
  // One iterator per field, in the order above.
  constexpr std::size_t kFields = 8;
  const char* const kNames[kFields] = {"x",      "y",      "z",      "cov_xx",
                                       "cov_xy", "cov_yy", "weight", "occupancy"};
  std::vector<sensor_msgs::PointCloud2Iterator<float>> it;
  for (const char* f : kNames) it.emplace_back(*msg, f);
  for (const wavog::NdtCell& c : layer.cells) {
    const double values[kFields] = {
        c.mean_x, c.mean_y, 0.0,      c.cov_xx,
        c.cov_xy, c.cov_yy, c.weight, wavog::probabilityFromLogOdds(c.log_odds)};
    for (std::size_t f = 0; f < kFields; ++f) {
      *it[f] = static_cast<float>(values[f]);
      ++it[f];
    }
  }
  return msg;
}

map_msgs::OccupancyGridUpdate::Ptr toOccupancyGridUpdateMsg(
    const wavog::Raster& raster, std::int64_t grid_min_x, std::int64_t grid_min_y,
    const wavog::GridValues& values, const std::string& frame, const ros::Time& stamp) {
  auto msg = boost::make_shared<map_msgs::OccupancyGridUpdate>();
  msg->header.frame_id = frame;
  msg->header.stamp = stamp;
  msg->x = static_cast<std::int32_t>(raster.box.min_x - grid_min_x);
  msg->y = static_cast<std::int32_t>(raster.box.min_y - grid_min_y);
  msg->width = static_cast<std::uint32_t>(raster.box.width());
  msg->height = static_cast<std::uint32_t>(raster.box.height());
  msg->data = wavog::toOccupancyGrid(raster, values);
  return msg;
}

}  // namespace wavog_ros
