// The laser-speed check of scan poses (see pose_check.h).
#include "wavog_mapping/ros/pose_check.h"

#include <cmath>
#include <sstream>

namespace wavog_ros {
namespace {

double distance(const wavog::Pose2& a, const wavog::Pose2& b) {
  return std::hypot(b.x - a.x, b.y - a.y);
}

}  // namespace

bool plausibleMove(const wavog::Pose2& a, double ta, const wavog::Pose2& b, double tb,
                   double max_speed) {
  const double d = distance(a, b);
  // Negated: NaN (a non-finite pose or time) is not plausible.
  return std::isfinite(d) && std::isfinite(b.theta) &&
         !(d > max_speed * std::abs(tb - ta) + kPoseSlack);
}

std::string PoseCheck::describe(const char* what, const wavog::Pose2& a, double ta,
                                const wavog::Pose2& b, double tb) const {
  std::ostringstream s;
  s.precision(3);
  s << "the laser would move " << distance(a, b) << " m in " << std::abs(tb - ta) << " s " << what
    << ", to (" << b.x << ", " << b.y << ") m: faster than max_sensor_speed " << max_speed_
    << " m/s (an absurd pose from tf)";
  return s.str();
}

std::string PoseCheck::check(const std::string& frame, const wavog::Pose2& start, double t0,
                             const wavog::Pose2& end, double t1) {
  if (!plausible(start, t0, start, t0) || !plausible(end, t1, end, t1)) {
    return "the laser's pose is not finite";
  }
  if (!plausible(start, t0, end, t1)) return describe("over its sweep", start, t0, end, t1);
  if (frames_.size() >= kMaxFrames && frames_.find(frame) == frames_.end()) frames_.clear();
  Frame& f = frames_[frame];
  if (f.have_accepted && !plausible(f.accepted.pose, f.accepted.t, start, t0)) {
    // A jump: refused, unless the last refused scan agrees with this one (a real jump, seen twice).
    const bool confirmed = f.have_refused && plausible(f.refused.pose, f.refused.t, start, t0);
    if (!confirmed) {
      std::string why = describe("since its last scan", f.accepted.pose, f.accepted.t, start, t0);
      f.have_refused = true;
      f.refused = {start, t0};
      return why;
    }
  }
  f.have_accepted = true;
  f.accepted = {end, t1};
  f.have_refused = false;
  return std::string();
}

}  // namespace wavog_ros
