// The report of wavog_compare: results.md (speed, work, memory, agreement, targets, repetition
// times, the machine) and results.csv (one row per workload and structure). Private to
// wavog_compare.
#ifndef WAVOG_MAPPING_TOOLS_COMPARE_REPORT_H_
#define WAVOG_MAPPING_TOOLS_COMPARE_REPORT_H_

#include <string>
#include <vector>

#include "compare/measure.h"
#include "compare/options.h"

namespace wavog_compare {

/// results.md's text.
std::string report(const std::vector<WorkloadResult>& results, const Options& opt);
/// Writes results.md (`text`) and results.csv to opt.out_dir; throws std::runtime_error naming the
/// folder when they cannot be written.
void writeResults(const std::vector<WorkloadResult>& results, const Options& opt,
                  const std::string& text);

}  // namespace wavog_compare

#endif  // WAVOG_MAPPING_TOOLS_COMPARE_REPORT_H_
