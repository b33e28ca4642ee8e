// Absurd laser poses from a real tf tree: odometry that jumps to 1e22 m for one sample and back
// (seen in a student robot's bag). tf interpolates between such a sample and its sane neighbours,
// so a scan near it is placed anywhere between the two: a pose inside the representable extent
// (and so integrated, far away, making the map too large to publish) as often as outside it. A
// laser does not move faster than max_sensor_speed (a parameter, 50 m/s by default): a scan whose
// pose implies more, against the last accepted scan of the same input and frame or between the
// first and last beam of its sweep, is refused. A real jump (a relocalisation, a restarted
// odometry) is confirmed by the next scan agreeing with the refused one, and mapping goes on from
// there. Plain values: the callers are MappingRos (which guards a PoseCheck with its lock) and
// wavog_offline's bag input; no ROS types.
#ifndef WAVOG_MAPPING_ROS_POSE_CHECK_H_
#define WAVOG_MAPPING_ROS_POSE_CHECK_H_

#include <map>
#include <string>

#include "wavog_mapping/core/types.h"

namespace wavog_ros {

/// Fastest plausible laser (m/s) by default (RosParams::max_sensor_speed): 180 km/h.
constexpr double kMaxSensorSpeed = 50.0;
/// Distance (m) always allowed between two poses, whatever the time between them (tf
/// interpolation and stamp jitter over short intervals).
constexpr double kPoseSlack = 1.0;

/// Whether a laser can move from pose a at time ta (s) to pose b at tb: the distance is finite and
/// at most max_speed (m/s) x |tb - ta| + kPoseSlack.
bool plausibleMove(const wavog::Pose2& a, double ta, const wavog::Pose2& b, double tb,
                   double max_speed = kMaxSensorSpeed);

/// One input's check: the last accepted pose of each laser frame, and the last refused one.
class PoseCheck {
 public:
  /// A check for lasers no faster than max_speed (m/s, > 0).
  explicit PoseCheck(double max_speed = kMaxSensorSpeed) : max_speed_(max_speed) {}

  /// The most frames remembered; beyond it the memory starts over (a frame met again is then
  /// accepted as new).
  static constexpr std::size_t kMaxFrames = 64;

  /// A scan of `frame` whose first beam was at `start` (time t0, s) and last at `end` (t1).
  /// Returns an empty string when it may be integrated (and remembers `end` as the frame's last
  /// accepted pose), else why not (e.g. "the laser would move 2.8e+07 m in 0.8 s ...").
  std::string check(const std::string& frame, const wavog::Pose2& start, double t0,
                    const wavog::Pose2& end, double t1);

 private:
  struct Stamped {
    wavog::Pose2 pose;
    double t = 0.0;
  };
  struct Frame {
    bool have_accepted = false;
    Stamped accepted;  ///< the last accepted scan's last beam
    bool have_refused = false;
    Stamped refused;  ///< the first beam of the last scan refused against `accepted`
  };
  bool plausible(const wavog::Pose2& a, double ta, const wavog::Pose2& b, double tb) const {
    return plausibleMove(a, ta, b, tb, max_speed_);
  }
  std::string describe(const char* what, const wavog::Pose2& a, double ta, const wavog::Pose2& b,
                       double tb) const;

  double max_speed_;
  std::map<std::string, Frame> frames_;
};

}  // namespace wavog_ros

#endif  // WAVOG_MAPPING_ROS_POSE_CHECK_H_
