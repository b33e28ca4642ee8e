// Motion compensation (see motion_compensation.h). Per beam: one interpolated pose, one rigid
// transform into the reference frame, one bin lookup; no allocation once the buffers have grown.
#include "wavog_mapping/core/motion_compensation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "wavog_mapping/core/limits.h"

namespace wavog {
namespace {

constexpr double kTwoPi = 2.0 * 3.14159265358979323846;

enum Rank : signed char { kEmpty = -1, kInvalid = 0, kNoReturn = 1, kReturn = 2 };

}  // namespace

double scanReach(const ScanView& scan, const SensorModelParams& sensor, double resolution) {
  // The core's hard range limit is at most kMaxRangeCells cells (limits.h): an upper bound.
  const double hard = kMaxRangeCells * resolution;
  const double given =
      sensor.max_range > 0.0 ? std::min(sensor.max_range, scan.range_max) : scan.range_max;
  const double range_max = std::min(given, hard);
  const double clear = std::min(sensor.no_return_clear, hard);
  double reach = 0.0;
  for (std::size_t i = 0; i < scan.count; ++i) {
    const double r = static_cast<double>(scan.ranges[i]);
    if (std::isnan(r) || r <= 0.0 || r < scan.range_min) continue;  // no information
    reach = std::max(reach, r >= range_max ? clear : r);
  }
  if (reach <= 0.0) return 0.0;
  return reach + std::max(sensor.band_width, resolution) + resolution;
}

ScanView MotionCompensator::compensate(const ScanView& scan, const Pose2& start, const Pose2& end,
                                       const Pose2& reference) {
  dropped_ = 0;
  const double inc = scan.angle_increment;
  // A scan the core refuses anyway (kBadGeometry, limits.h) is passed through untouched: its
  // size bounds the work and the buffers below.
  if (scan.count == 0 || scan.ranges == nullptr || !std::isfinite(inc) || inc == 0.0 ||
      scan.count > kMaxBeams) {
    return scan;
  }

  const std::size_t n = scan.count;
  if (n <= kScratchKeepBeams && ranges_.capacity() > kScratchKeepBeams) {
    // Buffers grown by an earlier absurd scan are released by the next ordinary one (the view
    // returned for the large scan pointed into them until now).
    std::vector<float>().swap(ranges_);
    std::vector<signed char>().swap(rank_);
  }
  ranges_.assign(n, std::numeric_limits<float>::quiet_NaN());
  rank_.assign(n, kEmpty);
  // A scan whose beams cover the whole circle wraps around instead of dropping at its ends.
  const bool full_circle = std::abs(inc) * static_cast<double>(n) >= kTwoPi - 0.5 * std::abs(inc);
  const double last = n > 1 ? static_cast<double>(n - 1) : 1.0;
  const double cos_r = std::cos(reference.theta), sin_r = std::sin(reference.theta);

  for (std::size_t i = 0; i < n; ++i) {
    const float r = scan.ranges[i];
    const double bearing = scan.angle_min + static_cast<double>(i) * inc;
    const Pose2 pose = interpolate(start, end, static_cast<double>(i) / last);
    Rank rank = kInvalid;
    double new_bearing =
        bearing + wrapAngle(pose.theta - reference.theta);  // directions only rotate
    float value = r;
    if (std::isnan(r) || r <= 0.0f || static_cast<double>(r) < scan.range_min) {
      rank = kInvalid;
    } else if (std::isinf(r) || static_cast<double>(r) >= scan.range_max) {
      rank = kNoReturn;
    } else {
      // Endpoint in the map frame, then in the reference frame.
      const double a = pose.theta + bearing;
      const double mx = pose.x + static_cast<double>(r) * std::cos(a) - reference.x;
      const double my = pose.y + static_cast<double>(r) * std::sin(a) - reference.y;
      const double rx = cos_r * mx + sin_r * my;
      const double ry = -sin_r * mx + cos_r * my;
      // Keep the bearing on the same branch as the original one, so fields of view that straddle
      // +-pi bin correctly.
      new_bearing = bearing + wrapAngle(std::atan2(ry, rx) - bearing);
      value = static_cast<float>(std::hypot(rx, ry));
      // Moving into the sensor's blind zone or out of its range changes the reading's class;
      // keep it a return only when it still is one.
      rank = (static_cast<double>(value) >= scan.range_min &&
              static_cast<double>(value) < scan.range_max)
                 ? kReturn
                 : kInvalid;
      if (rank == kInvalid) value = std::numeric_limits<float>::quiet_NaN();
    }
    auto bin = static_cast<long long>(std::llround((new_bearing - scan.angle_min) / inc));
    const auto count = static_cast<long long>(n);
    if (bin < 0 || bin >= count) {
      if (!full_circle) {
        ++dropped_;
        continue;
      }
      bin = ((bin % count) + count) % count;
    }
    const auto j = static_cast<std::size_t>(bin);
    // Priority: a return beats no return beats invalid beats empty; among returns, the nearest.
    if (rank > rank_[j] || (rank == kReturn && rank_[j] == kReturn && value < ranges_[j])) {
      rank_[j] = static_cast<signed char>(rank);
      ranges_[j] = value;
    }
  }

  ScanView out = scan;
  out.ranges = ranges_.data();
  return out;
}

}  // namespace wavog
