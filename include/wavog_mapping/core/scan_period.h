// ScanPeriod: the period of one laser's scans (ScanView::period, for forget_half_life), from the
// stamps of its successive scans. One object per laser; not thread-safe (one caller per laser).
#ifndef WAVOG_MAPPING_CORE_SCAN_PERIOD_H_
#define WAVOG_MAPPING_CORE_SCAN_PERIOD_H_

#include <cmath>

namespace wavog {

class ScanPeriod {
 public:
  /// Longest period taken from stamps or from the driver (s): a longer gap (a paused log, a
  /// laser restarted) must not forget a cell in one scan.
  static constexpr double kMaxPeriod = 1.0;

  /// The period of the scan stamped `stamp` (s): the time since the previous scan when in
  /// (0, kMaxPeriod]; else the driver's `scan_time` (sensor_msgs/LaserScan; 0 if none) when in
  /// (0, kMaxPeriod]; else 0, unknown (the scan then forgets by gamma).
  double next(double stamp, double scan_time = 0.0) {
    const double since = has_last_ ? stamp - last_ : 0.0;
    has_last_ = std::isfinite(stamp);
    if (has_last_) last_ = stamp;
    if (usable(since)) return since;
    return usable(scan_time) ? scan_time : 0.0;
  }

 private:
  static bool usable(double period) { return period > 0.0 && period <= kMaxPeriod; }

  double last_ = 0.0;
  bool has_last_ = false;
};

}  // namespace wavog

#endif  // WAVOG_MAPPING_CORE_SCAN_PERIOD_H_
