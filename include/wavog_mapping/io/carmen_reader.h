// Reader for CARMEN laser logs (FLASER, RLASER, ROBOTLASER1), plain text or gzip-compressed.
// Yields scans with laser and robot poses (map frame, m / rad) and time stamps (s).
// Not thread-safe; one reader per thread. Lives in the wavog_io library (std + zlib, no ROS).
#ifndef WAVOG_MAPPING_IO_CARMEN_READER_H_
#define WAVOG_MAPPING_IO_CARMEN_READER_H_

#include <cmath>
#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "wavog_mapping/core/types.h"

namespace wavog {

/// One laser scan of a CARMEN log.
struct CarmenScan {
  std::string type;               ///< "FLASER", "RLASER" or "ROBOTLASER1"
  std::size_t line = 0;           ///< 1-based line number in the log
  double ipc_timestamp = 0.0;     ///< ipc time stamp (s), as logged
  double logger_timestamp = 0.0;  ///< logger time stamp (s), as logged
  Pose2 laser_pose;               ///< laser pose in the map frame (corrected logs: corrected)
  Pose2 robot_pose;               ///< robot pose: odometry pose for FLASER/RLASER, robot pose for
                                  ///< ROBOTLASER1
  double angle_min = 0.0;         ///< bearing of the first beam in the laser frame (rad)
  double angle_increment = 0.0;   ///< bearing step (rad)
  double range_max = 0.0;  ///< readings at or above are no return (m), at most kNoReturnRange
  /// Ranges as logged (m). The no-return sentinels (81.91, ...) stay as logged: they are >=
  /// range_max, which is "no return" per REP 117 (see isNoReturn()).
  std::vector<float> ranges;
  /// A view for WaveletMap::integrate (valid while this object lives and is unchanged).
  ScanView view(double range_min = 0.0) const;
  /// True if beam reading `r` means "no return" for this scan (r >= range_max or +inf).
  bool isNoReturn(float r) const { return !std::isnan(r) && !(r < range_max); }
};

/// A line could not be parsed; what() is "<file>:<line>: <reason>".
class CarmenParseError : public std::runtime_error {
 public:
  CarmenParseError(const std::string& file, std::size_t line, const std::string& reason);
  std::size_t line() const { return line_; }

 private:
  std::size_t line_;
};

class CarmenReader {
 public:
  /// Opens `path` (gzip detected from the content). Throws std::runtime_error if unreadable.
  /// With `strict`, a malformed line throws CarmenParseError; otherwise it is counted, its message
  /// kept in errors(), and skipped.
  explicit CarmenReader(const std::string& path, bool strict = true);
  ~CarmenReader();
  CarmenReader(const CarmenReader&) = delete;
  CarmenReader& operator=(const CarmenReader&) = delete;

  /// Reads the next laser scan; false at the end of the log. Lines of other types are skipped.
  /// A truncated or corrupted gzip stream throws std::runtime_error naming the file.
  bool next(CarmenScan* scan);

  /// Messages of the malformed lines skipped so far (non-strict mode), "<file>:<line>: <reason>".
  const std::vector<std::string>& errors() const;

  /// True if the file is gzip-compressed (detected from its first two bytes).
  bool compressed() const;
  /// Lines read so far (all types, comments included).
  std::size_t linesRead() const;

  /// Range of the CARMEN "no return" sentinels: readings at or above it are no return (m).
  static constexpr double kNoReturnRange = 80.0;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Reads up to `max_scans` scans (0: all) of a log; throws like CarmenReader (strict mode).
std::vector<CarmenScan> readCarmenLog(const std::string& path, std::size_t max_scans = 0);

/// Directory of the shared data sets: $WAVOG_DATA_DIR if set, else the first of
/// ../shared/data, ../../shared/data ... found upwards from the current directory and from
/// `hint` (e.g. the source directory). Empty string if none is found.
std::string findDataDir(const std::string& hint = "");

}  // namespace wavog

#endif  // WAVOG_MAPPING_IO_CARMEN_READER_H_
