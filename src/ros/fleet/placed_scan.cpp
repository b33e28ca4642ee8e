// PlacedScan to and from the core call (see placed_scan.h).
#include "placed_scan.h"

#include <cmath>
#include <sstream>

#include "wavog_mapping/core/limits.h"
#include "wavog_mapping/core/scan_period.h"
#include "wavog_mapping/ros/conversions.h"

namespace wavog_fleet {
namespace {

/// The pose limits of the core, on every pose field of a message: finite, |theta| at most the
/// core's largest |angle_min| (bearings theta + angle stay exact), the position inside the extent.
bool poseInLimits(double x, double y, double theta, double resolution) {
  const double extent = static_cast<double>(wavog::kCellIndexLimit);
  // Negated comparisons: NaN is outside.
  return !(std::abs(x) / resolution >= extent) && !(std::abs(y) / resolution >= extent) &&
         std::isfinite(x) && std::isfinite(y) && std::abs(theta) <= wavog::kMaxAbsAngleMin;
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
    case Refusal::kBadStamp:
      return "bad_stamp";
    case Refusal::kBadPose:
      return "bad_pose";
    case Refusal::kBadSize:
      return "bad_size";
    case Refusal::kBadLength:
      return "bad_length";
  }
  return "unknown";
}

void fillPlacedScan(const ros::Time& stamp, const std::string& map_frame,
                    const std::string& vehicle, const std::string& input, std::uint64_t index,
                    const wavog::Pose2& pose, const wavog::ScanView& view, bool compensated,
                    const wavog::Pose2& start, const wavog::Pose2& end,
                    wavog_mapping::PlacedScan* m, const RangeCodec* codes) {
  m->version = codes ? wavog_mapping::PlacedScan::VERSION_UINT16
                     : wavog_mapping::PlacedScan::VERSION_FLOAT32;
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
  if (codes) {
    m->ranges.clear();
    m->range_codes = codes->codes();
    m->range_step = codes->step();
  } else {
    m->ranges.assign(view.ranges, view.ranges + view.count);
    m->range_codes.clear();
    m->range_step = 0.0;
  }
}

std::size_t placedBeams(const wavog_mapping::PlacedScan& m) {
  return m.version == wavog_mapping::PlacedScan::VERSION_UINT16 ? m.range_codes.size()
                                                                : m.ranges.size();
}

Refusal checkPlacedScan(const wavog_mapping::PlacedScan& m, const PlacedScanLimits& limits,
                        const ros::Time& now, std::string* detail) {
  std::ostringstream d;
  Refusal r = Refusal::kNone;
  const double offset = wavog_ros::secondsBetween(m.header.stamp, now);
  const bool codes = m.version == wavog_mapping::PlacedScan::VERSION_UINT16;
  const std::size_t beams = placedBeams(m);
  const double n_beams = static_cast<double>(beams);
  if (m.version != wavog_mapping::PlacedScan::VERSION_FLOAT32 && !codes) {
    d << "format version " << static_cast<int>(m.version) << ", this node reads "
      << static_cast<int>(wavog_mapping::PlacedScan::VERSION_FLOAT32) << " (float32 ranges) and "
      << static_cast<int>(wavog_mapping::PlacedScan::VERSION_UINT16) << " (16-bit codes)";
    r = Refusal::kVersion;
  } else if (m.header.frame_id != limits.map_frame) {
    d << "frame_id '" << m.header.frame_id << "', the fleet maps in '" << limits.map_frame << "'";
    r = Refusal::kFrame;
  } else if (m.header.stamp.isZero() || m.header.stamp.nsec >= 1000000000u ||
             !(std::abs(offset) <= limits.max_stamp_offset)) {
    d << "stamp " << m.header.stamp.sec << " s + " << m.header.stamp.nsec << " ns";
    if (m.header.stamp.nsec >= 1000000000u) {
      d << ": nsec not below 1e9";
    } else {
      d.precision(12);
      d << ", " << offset << " s from the fleet node's clock (" << now.sec << "." << now.nsec
        << " s), beyond fleet_max_stamp_offset " << limits.max_stamp_offset << " s";
      if (now.isZero()) d << " (the clock reads 0: use_sim_time without /clock?)";
    }
    r = Refusal::kBadStamp;
  } else if (!poseInLimits(m.x, m.y, m.theta, limits.resolution) ||
             !poseInLimits(m.start_x, m.start_y, m.start_theta, limits.resolution) ||
             !poseInLimits(m.end_x, m.end_y, m.end_theta, limits.resolution)) {
    d << "pose (" << m.x << ", " << m.y << ", " << m.theta << "), start (" << m.start_x << ", "
      << m.start_y << ", " << m.start_theta << "), end (" << m.end_x << ", " << m.end_y << ", "
      << m.end_theta << "): each must be finite, |theta| <= " << wavog::kMaxAbsAngleMin
      << " rad, |x|, |y| < " << static_cast<double>(wavog::kCellIndexLimit) * limits.resolution
      << " m (the map's extent)";
    r = Refusal::kBadPose;
  } else if (codes ? !m.ranges.empty() ||
                         !(m.range_step >= kRangeStep && m.range_step <= kMaxRangeStep)
                   : !m.range_codes.empty()) {
    d << "version " << static_cast<int>(m.version) << " with " << m.ranges.size()
      << " float ranges, " << m.range_codes.size() << " range codes, range_step "
      << m.range_step << " m: version 1 fills ranges only, version 2 range_codes only, with "
      << "range_step in [" << kRangeStep << ", " << kMaxRangeStep << "] m";
    r = Refusal::kBadSize;
  } else if (beams == 0 || beams > wavog::kMaxBeams ||
             !(std::abs(m.angle_min) <= wavog::kMaxAbsAngleMin) ||
             !(std::abs(m.angle_increment) >= wavog::kMinAbsAngleIncrement) ||
             !std::isfinite(m.angle_increment) ||
             std::abs(m.angle_increment) * n_beams > 2.0 * M_PI + 1e-6 ||
             !(m.range_min >= 0.0) || !std::isfinite(m.range_min) ||
             !(m.range_max > m.range_min)) {
    d << m.ranges.size() << " beams from angle_min " << m.angle_min << " by angle_increment "
      << m.angle_increment << " rad, range limits [" << m.range_min << ", " << m.range_max
      << "]: the core takes 1 to " << wavog::kMaxBeams << " beams, |angle_min| <= "
      << wavog::kMaxAbsAngleMin << " rad, |angle_increment| >= " << wavog::kMinAbsAngleIncrement
      << " rad, beams x |angle_increment| <= 2 pi, range_max > range_min >= 0";
    r = Refusal::kBadSize;
  } else if (!(m.period >= 0.0 && m.period <= wavog::ScanPeriod::kMaxPeriod)) {
    // No mapper sends it (wavog::ScanPeriod), and under forget_half_life a long one forgets
    // every cell of the scan's fan at once. Negated: NaN is refused.
    d << "period " << m.period << " s: a mapper sends 0 (unknown) or up to "
      << wavog::ScanPeriod::kMaxPeriod << " s (ScanPeriod::kMaxPeriod)";
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

wavog::ScanView placedView(const wavog_mapping::PlacedScan& m, std::vector<float>* decoded) {
  wavog::ScanView v;
  if (m.version == wavog_mapping::PlacedScan::VERSION_UINT16) {
    decodeRanges(m.range_codes.data(), m.range_codes.size(), m.range_step, decoded);
    v.ranges = decoded->data();
    v.count = decoded->size();
  } else {
    v.ranges = m.ranges.data();
    v.count = m.ranges.size();
  }
  v.angle_min = m.angle_min;
  v.angle_increment = m.angle_increment;
  v.range_min = m.range_min;
  v.range_max = m.range_max;
  v.period = m.period;
  return v;
}

}  // namespace wavog_fleet
