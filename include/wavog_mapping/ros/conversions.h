// Conversions between ROS messages and the core: LaserScan checks and views, tf -> planar pose,
// Raster -> OccupancyGrid. Stateless free functions: thread-safe.
#ifndef WAVOG_MAPPING_ROS_CONVERSIONS_H_
#define WAVOG_MAPPING_ROS_CONVERSIONS_H_

#include <geometry_msgs/Transform.h>
#include <map_msgs/OccupancyGridUpdate.h>
#include <nav_msgs/OccupancyGrid.h>
#include <sensor_msgs/LaserScan.h>

#include <cstddef>
#include <string>

#include "wavog_mapping/core/types.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog_ros {

/// Why a whole scan was dropped. Order = counter order in msg/InputStatus.msg.
enum class DropReason {
  kEmpty,          ///< no beams
  kSizeMismatch,   ///< ranges size disagrees with angle_min, angle_max, angle_increment
  kBadAngles,      ///< angle_increment zero or non-finite, or non-finite angle limits
  kBadFrame,       ///< empty frame_id (a leading '/' is stripped first: stripFrameSlash)
  kTfUnavailable,  ///< unknown frame, or tf did not arrive before the queue overflowed
  kTfTooOld,       ///< stamp older than the tf buffer
  kNoValidBeam,    ///< every beam invalid (REP 117): nothing to integrate
  kBadGeometry,    ///< refused by the core (bad range limits, non-finite pose, ...)
};
constexpr std::size_t kNumDropReasons = 8;

/// Short name of a drop reason ("empty", "size_mismatch", ...).
const char* toString(DropReason reason);

/// tf1-era drivers and bags write frame ids with a leading '/', which tf2 refuses: removes it.
/// Returns true if it did (the caller warns once per input that it does so).
bool stripFrameSlash(std::string* frame_id);
/// The text of that one warning, for the frame as received (e.g. "/laser").
std::string frameSlashWarning(const std::string& frame_id);

/// Checks what tf cannot: frame id, angles, size against the angles, emptiness. Returns false and
/// sets *reason when the scan must be dropped. Beam values are not checked (REP 117: the core
/// handles NaN and inf per beam).
bool checkScan(const sensor_msgs::LaserScan& scan, DropReason* reason);

/// Non-owning view of a checked scan (valid while the message lives).
wavog::ScanView toScanView(const sensor_msgs::LaserScan& scan);

/// Planar pose (map frame) of a sensor from its 3D transform map <- sensor. A sensor mounted upside
/// down (its z axis pointing down) sees the plane mirrored: *mirrored is set and the scan's view
/// must go through mirrorView().
wavog::Pose2 toPose2(const geometry_msgs::Transform& transform, bool* mirrored);

/// Mirrors a view's bearings (angle_min and angle_increment change sign).
void mirrorView(wavog::ScanView* view);

/// The raster as an OccupancyGrid in `frame` (origin = raster origin, identity orientation,
/// row-major from the lowest y, -1 unknown, 0..100 graded).
nav_msgs::OccupancyGrid::Ptr toOccupancyGridMsg(const wavog::Raster& raster,
                                                const std::string& frame, const ros::Time& stamp);

/// The raster as an update of a grid whose cell (0, 0) is the scale-s cell (grid_min_x,
/// grid_min_y): x, y are the raster's offsets in that grid.
map_msgs::OccupancyGridUpdate::Ptr toOccupancyGridUpdateMsg(const wavog::Raster& raster,
                                                            std::int64_t grid_min_x,
                                                            std::int64_t grid_min_y,
                                                            const std::string& frame,
                                                            const ros::Time& stamp);

}  // namespace wavog_ros

#endif  // WAVOG_MAPPING_ROS_CONVERSIONS_H_
