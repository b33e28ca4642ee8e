// Basic value types of the ROS-free core: the planar pose and its algebra, non-owning scan views,
// cell indices, cell classes and scan statuses.
// Units are SI (metres, radians, seconds). All types are plain values, safe to copy between
// threads.
#ifndef WAVOG_MAPPING_CORE_TYPES_H_
#define WAVOG_MAPPING_CORE_TYPES_H_

#include <cstddef>
#include <cstdint>

namespace wavog {

/// A planar pose: position (m) and heading (rad) of a frame in the map frame.
struct Pose2 {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;
};

/// Angle wrapped to (-pi, pi]. The package's one angle wrap.
double wrapAngle(double a);
/// Composition a * b: pose b (given relative to frame a) expressed in a's parent frame.
Pose2 compose(const Pose2& a, const Pose2& b);
/// The inverse transform of a: inverse(a) * a is the identity.
Pose2 inverse(const Pose2& a);
/// Pose at fraction f of the way from a (f = 0) to b (f = 1): linear in position, along the
/// shorter arc in heading.
Pose2 interpolate(const Pose2& a, const Pose2& b, double f);

/// A non-owning view of one planar range scan in its sensor frame, laid out like
/// sensor_msgs/LaserScan: beam i points at bearing angle_min + i * angle_increment.
/// Readings follow REP 117: +inf and readings >= range_max are "no return"; NaN, -inf and
/// readings < range_min (or <= 0) carry no information.
struct ScanView {
  const float* ranges = nullptr;  ///< beam ranges (m); `count` values
  std::size_t count = 0;          ///< number of beams
  double angle_min = 0.0;         ///< bearing of beam 0 in the sensor frame (rad)
  double angle_increment = 0.0;   ///< bearing step between beams (rad), non-zero, may be < 0
  double range_min = 0.0;         ///< readings below are invalid (m)
  double range_max = 0.0;         ///< readings at or above are "no return" (m)
  /// Time since the previous scan of the same laser (s), for PolicyParams::forget_half_life;
  /// 0, negative or non-finite: unknown (the scan then forgets by gamma).
  double period = 0.0;
};

/// Integer index of a finest cell: cell (ix, iy) covers [ix, ix+1) x [iy, iy+1) * resolution.
struct CellIndex {
  std::int64_t x = 0;
  std::int64_t y = 0;
  bool operator==(const CellIndex& o) const { return x == o.x && y == o.y; }
};

/// A half-open box of cells at some scale s: [min_x, max_x) x [min_y, max_y), in units of
/// 2^s finest cells. Used for read-out windows.
struct CellBox {
  std::int64_t min_x = 0;
  std::int64_t min_y = 0;
  std::int64_t max_x = 0;
  std::int64_t max_y = 0;
  std::int64_t width() const { return max_x - min_x; }
  std::int64_t height() const { return max_y - min_y; }
  bool empty() const { return max_x <= min_x || max_y <= min_y; }
};

/// Class of a cell, or of a node, against one scan (ALGORITHM.md section 3.2).
enum class CellClass : std::uint8_t {
  kUnknown,        ///< U: the scan says nothing about it
  kEmpty,          ///< E: entirely in the scan's free space
  kOccupied,       ///< O: in the band around a hit (finest cells only)
  kFreeOrUnknown,  ///< nodes only: E and U parts, no O
  kMixed,          ///< nodes only: may contain O (conservative)
};

/// Why a whole scan was refused by the core (it then changes nothing).
enum class ScanStatus : std::uint8_t {
  kOk,
  kEmpty,        ///< no beams
  kBadGeometry,  ///< angle_min or angle_increment non-finite or absurd (limits.h), field of view
                 ///< > 2 pi, more than kMaxBeams beams, bad range limits
  kBadPose,      ///< non-finite sensor pose
  kNoValidBeam,  ///< every beam is invalid: nothing to integrate (map unchanged)
  kOutOfExtent,  ///< the sensor pose plus the scan's range limit (or no-return clearing
                 ///< distance) leaves the representable extent (kCellIndexLimit, limits.h)
};

/// Human-readable name of a ScanStatus, for logs and counters.
const char* toString(ScanStatus status);

}  // namespace wavog

#endif  // WAVOG_MAPPING_CORE_TYPES_H_
