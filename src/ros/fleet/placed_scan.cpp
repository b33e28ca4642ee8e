// PlacedScan to and from the core call (see placed_scan.h).
#include "placed_scan.h"

#include <cmath>
#include <sstream>

#include "wavog_mapping/core/limits.h"

namespace wavog_fleet {
namespace {

/// Largest |coordinate| (m) a fleet node takes; the core refuses a pose far inside it anyway.
constexpr double kMaxCoordinate = 1e9;

bool finitePose(double x, double y, double theta) {
  return std::isfinite(x) && std::isfinite(y) && std::isfinite(theta) &&
         std::abs(x) < kMaxCoordinate && std::abs(y) < kMaxCoordinate;
}

}  // namespace

const char* toString(Refusal r) {
  switch (r) {
    case Refusal::kNone:
      return "none";
    case Refusal::kVersion:
      return "version";
    case Refusal::kFrame:
      return "frame";
    case Refusal::kBadPose:
      return "bad_pose";
    case Refusal::kBadSize:
      return "bad_size";
  }
  return "unknown";
}

void fillPlacedScan(const ros::Time& stamp, const std::string& map_frame,
                    const std::string& vehicle, const std::string& input, std::uint64_t index,
                    const wavog::Pose2& pose, const wavog::ScanView& view, bool compensated,
                    const wavog::Pose2& start, const wavog::Pose2& end,
                    wavog_mapping::PlacedScan* m) {
  m->version = wavog_mapping::PlacedScan::FORMAT_VERSION;
  m->header.stamp = stamp;
  m->header.frame_id = map_frame;
  m->vehicle = vehicle;
  m->input = input;
  m->index = index;
  m->x = pose.x;
  m->y = pose.y;
  m->theta = pose.theta;
  m->compensated = compensated;
  m->start_x = start.x;
  m->start_y = start.y;
  m->start_theta = start.theta;
  m->end_x = end.x;
  m->end_y = end.y;
  m->end_theta = end.theta;
  m->angle_min = view.angle_min;
  m->angle_increment = view.angle_increment;
  m->range_min = view.range_min;
  m->range_max = view.range_max;
  m->period = view.period;
  m->ranges.assign(view.ranges, view.ranges + view.count);
}

Refusal checkPlacedScan(const wavog_mapping::PlacedScan& m, const std::string& map_frame,
                        std::string* detail) {
  std::ostringstream d;
  Refusal r = Refusal::kNone;
  if (m.version != wavog_mapping::PlacedScan::FORMAT_VERSION) {
    d << "format version " << static_cast<int>(m.version) << ", this node reads "
      << static_cast<int>(wavog_mapping::PlacedScan::FORMAT_VERSION);
    r = Refusal::kVersion;
  } else if (m.header.frame_id != map_frame) {
    d << "frame_id '" << m.header.frame_id << "', the fleet maps in '" << map_frame << "'";
    r = Refusal::kFrame;
  } else if (m.header.stamp.isZero() || !finitePose(m.x, m.y, m.theta) ||
             !std::isfinite(m.angle_min) || !std::isfinite(m.angle_increment) ||
             std::abs(m.angle_min) > wavog::kMaxAbsAngleMin ||
             std::abs(m.angle_increment) < wavog::kMinAbsAngleIncrement) {
    d << "pose (" << m.x << ", " << m.y << ", " << m.theta << "), angle_min " << m.angle_min
      << ", angle_increment " << m.angle_increment << ", stamp " << m.header.stamp.sec << "."
      << m.header.stamp.nsec;
    r = Refusal::kBadPose;
  } else if (m.ranges.empty() || m.ranges.size() > wavog::kMaxBeams ||
             std::abs(m.angle_increment) * static_cast<double>(m.ranges.size() - 1) >
                 2.0 * M_PI + 1e-6 ||
             !(m.range_min >= 0.0) || !(m.range_max > m.range_min)) {
    d << m.ranges.size() << " beams over " << std::abs(m.angle_increment) *
                                                  static_cast<double>(m.ranges.size())
      << " rad, range limits [" << m.range_min << ", " << m.range_max << "]";
    r = Refusal::kBadSize;
  }
  if (detail) *detail = d.str();
  return r;
}

wavog::Pose2 placedPose(const wavog_mapping::PlacedScan& m) {
  wavog::Pose2 p;
  p.x = m.x;
  p.y = m.y;
  p.theta = m.theta;
  return p;
}

wavog::ScanView placedView(const wavog_mapping::PlacedScan& m) {
  wavog::ScanView v;
  v.ranges = m.ranges.data();
  v.count = m.ranges.size();
  v.angle_min = m.angle_min;
  v.angle_increment = m.angle_increment;
  v.range_min = m.range_min;
  v.range_max = m.range_max;
  v.period = m.period;
  return v;
}

}  // namespace wavog_fleet
