// What the node says when tf cannot place a scan (issue 41): the frame that is missing, not just
// the map frame, with the frames tf does have; and, when the end of a sweep has no tf yet, that
// tf_tolerance is shorter than the sweep. Functions of the tf buffer's contents: reentrant (the
// buffer locks itself), no roscore needed.
#ifndef WAVOG_MAPPING_SRC_ROS_TF_MESSAGES_H_
#define WAVOG_MAPPING_SRC_ROS_TF_MESSAGES_H_

#include <tf2/buffer_core.h>

#include <string>

namespace wavog_ros {

/// The frames `tf` holds, comma-separated and sorted, at most `max_listed` of them ("... and N
/// more"); "none" when it holds none.
std::string framesOf(const tf2::BufferCore& tf, std::size_t max_listed = 12);

/// Why a scan in `scan_frame` has no transform to `fixed_frame` (the tf filter gave up): the
/// frame tf does not have (the scan's, or the map frame) with the frames it has; or, both known,
/// whether tf connects them at all; `queue_size` is the filter's (more scans waiting for tf than
/// this drops the oldest).
std::string noTransformText(const tf2::BufferCore& tf, const std::string& scan_frame,
                            const std::string& fixed_frame, int queue_size);

/// A scan placed without motion compensation because tf did not reach the end of its sweep
/// (`sweep`, s) while it waited at most as the scans waiting for tf do (`queue_size`: the
/// filter's).
std::string motionFallbackText(int queue_size, double sweep);

}  // namespace wavog_ros

#endif  // WAVOG_MAPPING_SRC_ROS_TF_MESSAGES_H_
