// The workloads of wavog_compare: scans of the CARMEN logs (every n-th, up to a count) and a
// synthetic arena seen by four LMS-291 at 60-80 m, each at every resolution asked for. Private to
// wavog_compare.
#ifndef WAVOG_MAPPING_TOOLS_COMPARE_WORKLOADS_H_
#define WAVOG_MAPPING_TOOLS_COMPARE_WORKLOADS_H_

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "compare/options.h"
#include "wavog_mapping/core/types.h"

namespace wavog_compare {

/// One scan with its own storage.
struct Scan {
  wavog::Pose2 pose;  ///< laser pose, map frame
  std::vector<float> ranges;
  double angle_min = 0.0;
  double angle_increment = 0.0;
  double range_min = 0.0;
  double range_max = 0.0;
  wavog::ScanView view() const {
    return wavog::ScanView{ranges.data(),   ranges.size(), angle_min,
                           angle_increment, range_min,     range_max};
  }
};

struct Workload {
  std::string name;   ///< short name for files
  std::string label;  ///< table label
  double resolution = 0.05;
  std::vector<Scan> scans;
  std::size_t timed_scans = 0;  ///< scans per timed repetition (a prefix of `scans`)
};

/// Every `stride`-th scan of a log, up to `max_scans` scans (0: all).
std::vector<Scan> loadLog(const std::string& path, std::size_t stride, std::size_t max_scans);

/// Four LMS-291 (361 beams over 180 deg, 0.5 deg, range_max 80 m) on a vehicle that creeps and
/// turns in the middle of an open arena whose boundary lies 60-80 m away: every beam returns at
/// 60-80 m. Four scans per step (front, rear, left, right), 1 cm Gaussian range noise, fixed seed.
std::vector<Scan> syntheticLms291x4(int steps);

/// Calls `run` with each workload of `opt` (workload x resolution), one at a time. A missing log
/// is skipped in smoke runs and an error (std::runtime_error) otherwise.
void forEachWorkload(const Options& opt, const std::function<void(const Workload&)>& run);

}  // namespace wavog_compare

#endif  // WAVOG_MAPPING_TOOLS_COMPARE_WORKLOADS_H_
