// Definitions of the basic value types (types.h): names of scan statuses, planar pose algebra.
#include "wavog_mapping/core/types.h"

#include <cmath>
#include <cstddef>

namespace wavog {
namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

const char* toString(ScanStatus status) {
  // In the order of the enumerators.
  constexpr const char* kNames[] = {"ok",       "empty_scan",    "bad_geometry",
                                    "bad_pose", "no_valid_beam", "out_of_extent"};
  const auto i = static_cast<std::size_t>(status);
  return i < sizeof(kNames) / sizeof(kNames[0]) ? kNames[i] : "unknown";
}

double wrapAngle(double a) {
  a = std::remainder(a, 2.0 * kPi);  // in [-pi, pi]
  return a <= -kPi ? a + 2.0 * kPi : a;
}

Pose2 compose(const Pose2& a, const Pose2& b) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  return {a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, wrapAngle(a.theta + b.theta)};
}

Pose2 inverse(const Pose2& a) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  return {-c * a.x - s * a.y, s * a.x - c * a.y, wrapAngle(-a.theta)};
}

Pose2 interpolate(const Pose2& a, const Pose2& b, double f) {
  return {a.x + f * (b.x - a.x), a.y + f * (b.y - a.y),
          wrapAngle(a.theta + f * wrapAngle(b.theta - a.theta))};
}

}  // namespace wavog
