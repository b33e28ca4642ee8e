// noTransformText, motionFallbackText (see tf_messages.h).
#include "tf_messages.h"

#include <algorithm>
#include <sstream>
#include <vector>

namespace wavog_ros {

std::string framesOf(const tf2::BufferCore& tf, std::size_t max_listed) {
  std::vector<std::string> frames;
  tf._getFrameStrings(frames);
  if (frames.empty()) return "none";
  std::sort(frames.begin(), frames.end());
  std::string out;
  for (std::size_t i = 0; i < frames.size() && i < max_listed; ++i) {
    out += (i ? ", " : "") + frames[i];
  }
  if (frames.size() > max_listed) {
    out += " and " + std::to_string(frames.size() - max_listed) + " more";
  }
  return out;
}

std::string noTransformText(const tf2::BufferCore& tf, const std::string& scan_frame,
                            const std::string& fixed_frame, int queue_size) {
  const std::string have = " (frames tf has: " + framesOf(tf) + ")";
  if (!tf._frameExists(scan_frame)) {
    return "no transform to '" + fixed_frame + "': the scan's frame '" + scan_frame +
           "' is not in tf" + have +
           "; publish the laser's mount (URDF, a static transform), or start with "
           "laser_parent:=<frame> laser_frame:=" +
           scan_frame + " laser_pose:=\"x y z yaw pitch roll\"";
  }
  if (!tf._frameExists(fixed_frame)) {
    return "no transform from '" + scan_frame + "': the map frame '" + fixed_frame +
           "' is not in tf" + have + "; set map_frame to one of them";
  }
  std::string why;
  if (!tf.canTransform(fixed_frame, scan_frame, ros::Time(0), &why)) {
    return "no transform from '" + scan_frame + "' to '" + fixed_frame +
           "': tf does not connect them" + have;
  }
  return "no transform from '" + scan_frame + "' to '" + fixed_frame +
         "' at the scan's stamp (tf connects them, but not in time: tf late, or more than "
         "queue_size " +
         std::to_string(queue_size) + " scans waiting for tf)";
}

std::string motionFallbackText(int queue_size, double sweep) {
  std::ostringstream s;
  s << "tf did not reach the end of the sweep (" << sweep << " s after the scan's stamp) while "
    << "the scan waited for it (more than queue_size " << queue_size
    << " later scans placed, or the wait's bounds): placed without motion compensation. tf "
       "stopping short of every sweep means a wrong time_increment, or set motion_compensation: "
       "false";
  return s.str();
}

}  // namespace wavog_ros
