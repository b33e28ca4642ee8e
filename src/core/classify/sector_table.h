// The sector of a direction without trigonometry: a table over a cheap, monotone sensor-frame
// pseudo-bearing (dy / (|dx| + |dy|) per half-plane, one division), built once per scan
// geometry (beams, angle_min, angle_increment) and kept while it does not change. A bucket of
// the table that no sector boundary comes near holds the sector of every direction in it,
// exactly: the one the reference's lround gives (ALGORITHM.md 3.1). The other buckets (a
// boundary within kPseudoMargin) say kUnsure, and the classifier decides those directions as
// before (boundary cross products, or the bearing). Not installed; included only by src/core/*
// and the core tests.
#ifndef WAVOG_MAPPING_SRC_CORE_CLASSIFY_SECTOR_TABLE_H_
#define WAVOG_MAPPING_SRC_CORE_CLASSIFY_SECTOR_TABLE_H_

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace wavog {
namespace detail {

class SectorTable {
 public:
  /// A bucket that a boundary comes near.
  static constexpr std::int32_t kUnsure = -1;
  /// Margin around each boundary's pseudo-bearing (pseudo-bearing units, at most radians): twice
  /// the classifier's kRayMargin, far above the rounding of the pseudo-bearings (under 1e-15) and
  /// of the boundary directions (under 1e-12 rad).
  static constexpr double kPseudoMargin = 2e-9;
  /// Beam steps above this get no table (every bucket kUnsure): real scanners step far less.
  static constexpr double kMaxStep = 0.25;
  static constexpr double kSmallestNormal = 2.2250738585072014e-308;

  /// Fills the table for n beams at bearings amin + j inc (inc > 0, sensor frame), unless it
  /// holds that geometry already: sector j between the boundaries at amin + (j -+ 1/2) inc. A
  /// bucket outside the fan holds n (no beam: U).
  void prepare(int n, double amin, double inc);
  /// Releases the table's memory.
  void release() {
    std::vector<std::int32_t>().swap(sector_);
    n_ = -1;
  }
  std::size_t buckets() const { return sector_.size(); }

  /// A pseudo-bearing of direction (dx, dy) in [0, 4], increasing with the angle from +x
  /// counter-clockwise over [0, 2 pi) (4 only by rounding just below +x); (0, 0) gives 0. Its
  /// slope against the angle lies between 1/2 and 1, so pseudo-bearings closer than an angle.
  static double pseudoBearing(double dx, double dy) {
    // A cell's offset is 0 or far above the smallest normal double (resolution > 1 mm), so the
    // floor only turns 0 / 0 into 0; as a max, it keeps the loops over cells vectorisable.
    const double s = std::max(std::fabs(dx) + std::fabs(dy), kSmallestNormal);
    const double r = dy / s;  // in [-1, 1]
    // 2 - r, 4 + r or r, written as selects so that loops over cells vectorise.
    const double base = dx < 0.0 ? 2.0 : (dy < 0.0 ? 4.0 : 0.0);
    return base + (dx < 0.0 ? -r : r);
  }
  /// The bucket of sensor-frame direction (dx, dy).
  std::uint32_t bucket(double dx, double dy) const {
    // In [0, buckets]: the top one (4) wraps to the first, just past +x.
    return static_cast<std::uint32_t>(static_cast<std::int32_t>(pseudoBearing(dx, dy) * scale_)) &
           mask_;
  }
  /// The sector of every direction of bucket b (n outside the fan), or kUnsure.
  std::int32_t at(std::uint32_t b) const { return sector_[b]; }
  const std::int32_t* data() const { return sector_.data(); }
  std::uint32_t mask() const { return mask_; }
  /// Buckets per unit of pseudo-bearing (a power of two).
  double scale() const { return scale_; }
  /// The sector of sensor-frame direction (dx, dy) (n outside the fan), or kUnsure.
  std::int32_t sector(double dx, double dy) const { return sector_[bucket(dx, dy)]; }

 private:
  void build(int n, double amin, double inc);

  std::vector<std::int32_t> sector_;
  int n_ = -1;  // the geometry the table holds
  double amin_ = 0, inc_ = 0;
  double scale_ = 0;        // buckets / 4
  std::uint32_t mask_ = 0;  // buckets - 1 (a power of two)
};

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_CLASSIFY_SECTOR_TABLE_H_
