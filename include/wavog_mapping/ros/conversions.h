// Conversions between ROS messages and the core: LaserScan checks and views, tf -> planar pose,
// Raster -> OccupancyGrid, NdtLayer -> MarkerArray / PointCloud2. Stateless free functions:
// thread-safe.
#ifndef WAVOG_MAPPING_ROS_CONVERSIONS_H_
#define WAVOG_MAPPING_ROS_CONVERSIONS_H_

#include <geometry_msgs/Transform.h>
#include <map_msgs/OccupancyGridUpdate.h>
#include <nav_msgs/OccupancyGrid.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/MarkerArray.h>

#include <cstddef>
#include <string>

#include "wavog_mapping/core/types.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog_ros {

/// Why a whole scan was dropped. Order = counter order in msg/InputStatus.msg.
enum class DropReason {
  kEmpty,          ///< no beams
  kBadAngles,      ///< angle_increment zero or non-finite, or angle_min non-finite
  kBadFrame,       ///< empty frame_id (a leading '/' is stripped first: stripFrameSlash)
  kTfUnavailable,  ///< unknown frame, or tf did not arrive before the queue overflowed
  kTfTooOld,       ///< stamp older than the tf buffer
  kNoValidBeam,    ///< no beam to integrate: each invalid, or a no return (REP 117)
  kBadGeometry,    ///< refused by the core: a limit of limits.h (angles, beams, range limits)
  kOutOfExtent,    ///< refused by the core: pose plus reach outside the representable extent
  kAbsurdPose,     ///< the laser's pose jumps faster than max_sensor_speed, or is not finite
  kBadTime,        ///< stamp or time_increment outside what ROS time arithmetic can represent
  kException,      ///< an exception was caught while handling the scan (logged)
  kBadLength,      ///< an array longer than the message's bytes, or a truncated message:
                   ///< refused before deserialisation sized anything (checked_subscription.h)
};
constexpr std::size_t kNumDropReasons = 12;

/// Longest sweep (s), |time_increment| x (beams - 1), of a scan that is accepted; a longer one, or
/// a non-finite time_increment, is dropped as bad_time. Planar lasers sweep in 10-200 ms.
constexpr double kMaxSweepSeconds = 10.0;

/// a - b in seconds. Never throws (ros::Time's operator- throws beyond 2^31 s).
double secondsBetween(const ros::Time& a, const ros::Time& b);

/// t + seconds into *out; false (and *out untouched) when seconds is non-finite or the sum falls
/// outside [0, 2^32) s, where ros::Time arithmetic would throw. Never throws.
bool addSeconds(const ros::Time& t, double seconds, ros::Time* out);

/// Whether the tf buffer can take a transform stamped `stamp` with a cache of `cache_time` s: its
/// pruning adds cache_time to the stamps and throws beyond 2^32 s. Never throws.
bool tfStampUsable(const ros::Time& stamp, double cache_time);

/// Sweep duration (s) of a scan: time_increment x (beams - 1); 0 for fewer than 2 beams.
double sweepSeconds(const sensor_msgs::LaserScan& scan);

/// Checks the time fields of a scan that passed checkScan(): the stamp plus `tolerance` (the tf
/// filter's) and plus the sweep must be representable, time_increment finite and the sweep at
/// most kMaxSweepSeconds. Returns false and sets *reason (kBadTime) otherwise. Never throws.
bool checkScanTime(const sensor_msgs::LaserScan& scan, double tolerance, DropReason* reason);

/// Short name of a drop reason ("empty", "bad_angles", ...).
const char* toString(DropReason reason);

/// tf1-era drivers and bags write frame ids with a leading '/', which tf2 refuses: removes it.
/// Returns true if it did (the caller warns once per input that it does so).
bool stripFrameSlash(std::string* frame_id);
/// The text of that one warning, for the frame as received (e.g. "/laser").
std::string frameSlashWarning(const std::string& frame_id);

/// Checks what tf cannot: frame id, angle_min and angle_increment, emptiness. Returns false and
/// sets *reason when the scan must be dropped. Beam values are not checked (REP 117: the core
/// handles NaN and inf per beam), nor is angle_max: as laser_geometry (so costmap_2d),
/// Cartographer and hector_mapping do, beam i lies at angle_min + i * angle_increment for every
/// range of the message (beamCountMismatch() tells when angle_max disagrees).
bool checkScan(const sensor_msgs::LaserScan& scan, DropReason* reason);

/// Beams that angle_min, angle_max and angle_increment imply: (max - min) / increment + 1 (NaN
/// when they are not finite).
double impliedBeams(const sensor_msgs::LaserScan& scan);
/// Whether the range count disagrees with impliedBeams() by more than one beam (drivers round
/// angle_max, or write the end of the last beam's sector: one beam of slack). Such a scan is
/// integrated as the ecosystem places it (counted, warned).
bool beamCountMismatch(const sensor_msgs::LaserScan& scan);
/// Whether intensities are present with another length than ranges (ignored; the mapper does not
/// read them: counted, warned).
bool intensitiesMismatch(const sensor_msgs::LaserScan& scan);

/// Relative excess over 2 pi of beams x |angle_increment| that is taken as a full turn whose
/// increment the driver rounded up (e.g. 64 beams of 0.098175 rad: 2 pi + 1.4e-5): the increment
/// becomes 2 pi / beams (moving the last beam by less than beams x 1e-4 x 2 pi / beams).
constexpr double kFullTurnSlack = 1e-4;

/// Non-owning view of a checked scan (valid while the message lives). A full turn whose increment
/// is rounded up within kFullTurnSlack is spread over exactly 2 pi (the core refuses a field of
/// view beyond 2 pi).
wavog::ScanView toScanView(const sensor_msgs::LaserScan& scan);

/// Why the core refused a view as ScanStatus::kBadGeometry: the limit (limits.h) it broke and the
/// value, e.g. "range_max 10 is not above range_min 50".
std::string geometryRefusal(const wavog::ScanView& view);

/// What the log says of a scan the core refused (st.status != kOk): the status and the numbers
/// behind it: for kNoValidBeam the beams invalid, no return and beyond the hard range limit (with
/// that limit), for kOutOfExtent the pose and the extent, for kBadGeometry geometryRefusal().
std::string coreRefusal(const wavog::IntegrateStats& st, const wavog::ScanView& view,
                        const wavog::Pose2& pose, const wavog::MapParams& params);

/// Planar pose (map frame) of a sensor from its 3D transform map <- sensor. A sensor mounted upside
/// down (its z axis pointing down) sees the plane mirrored: *mirrored is set and the scan's view
/// must go through mirrorView().
wavog::Pose2 toPose2(const geometry_msgs::Transform& transform, bool* mirrored);

/// Mirrors a view's bearings (angle_min and angle_increment change sign).
void mirrorView(wavog::ScanView* view);

/// Most cells of one published layer or saved image: 2^24 (16.8 M cells, e.g. 4096 x 4096, about
/// 100 MB while it is read out and sent). A larger layer is refused (counted, logged), never
/// allocated; publish_window bounds what is published.
constexpr double kMaxLayerCells = 16777216.0;

/// What layerBox() found.
enum class LayerSize { kEmpty, kOk, kTooLarge };

/// The box of scale-s cells one layer publishes: the map's bounds (window <= 0), or the square of
/// half-width `window` around (cx, cy), clipped to the bounds grown by the window (no change while
/// the robot is on the map; a centre far off the map, or not finite, gives an empty layer) and,
/// when it would hold more than kMaxLayerCells, to the bounds. kTooLarge (*box the refused box)
/// when the result holds more than kMaxLayerCells. Allocates nothing, never throws.
LayerSize layerBox(const wavog::WaveletMap& map, int scale, double window, double cx, double cy,
                   wavog::CellBox* box);

/// The raster as an OccupancyGrid in `frame` (origin = raster origin, identity orientation,
/// row-major from the lowest y), its values by `values` (trinary 0 / 100 / -1, or graded).
nav_msgs::OccupancyGrid::Ptr toOccupancyGridMsg(const wavog::Raster& raster,
                                                const wavog::GridValues& values,
                                                const std::string& frame, const ros::Time& stamp);
/// Reflection probabilities as an OccupancyGrid (0..100 from p, -1 where never observed).
nav_msgs::OccupancyGrid::Ptr toOccupancyGridMsg(const wavog::ReflectionRaster& raster,
                                                const std::string& frame, const ros::Time& stamp);

/// Thickness (m) of an NDT ellipse marker, and the smallest axis of one, as a fraction of the
/// layer's cell size (a cell of one end-point has covariance 0 and would not be drawn).
constexpr double kNdtMarkerThickness = 0.01;
constexpr double kNdtMinAxisCells = 0.1;

/// The axes of the 2-sigma ellipse of a 2D covariance [[xx, xy], [xy, yy]]: *major, *minor are
/// the full lengths (4 sqrt(eigenvalue), m), *yaw the angle (rad) of the major axis from x.
void ndtEllipse(double cov_xx, double cov_xy, double cov_yy, double* major, double* minor,
                double* yaw);

/// The NDT cells of one layer for rviz: a DELETEALL first (the layer replaces the last one as a
/// whole), then per Gaussian a flat CYLINDER in `frame`, namespace "ndt_scale_<s>", id 1, 2, ...
/// in the layer's order: at the mean, yawed along the major axis, its 2-sigma ellipse
/// (ndtEllipse; each axis at least kNdtMinAxisCells x cell size), coloured from blue (P(occ) 0)
/// to red (P(occ) 1) by the cell's occupancy.
visualization_msgs::MarkerArray::Ptr toNdtMarkers(const wavog::NdtLayer& layer,
                                                  const std::string& frame, const ros::Time& stamp);

/// The NDT cells of one layer as an unorganised cloud (height 1, one point per Gaussian, the
/// layer's order) with float32 fields x, y (the mean, m), z (0, so that rviz and PCL take it),
/// cov_xx, cov_xy, cov_yy (m^2), weight and occupancy (P(occ) of the cell, 0..1), in `frame`.
sensor_msgs::PointCloud2::Ptr toNdtCloud(const wavog::NdtLayer& layer, const std::string& frame,
                                         const ros::Time& stamp);

/// The raster as an update of a grid whose cell (0, 0) is the scale-s cell (grid_min_x,
/// grid_min_y): x, y are the raster's offsets in that grid.
map_msgs::OccupancyGridUpdate::Ptr toOccupancyGridUpdateMsg(
    const wavog::Raster& raster, std::int64_t grid_min_x, std::int64_t grid_min_y,
    const wavog::GridValues& values, const std::string& frame, const ros::Time& stamp);

}  // namespace wavog_ros

#endif  // WAVOG_MAPPING_ROS_CONVERSIONS_H_
