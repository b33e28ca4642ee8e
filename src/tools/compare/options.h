// The command line of wavog_compare: which workloads, resolutions, repetitions and pictures.
// Private to wavog_compare.
#ifndef WAVOG_MAPPING_TOOLS_COMPARE_OPTIONS_H_
#define WAVOG_MAPPING_TOOLS_COMPARE_OPTIONS_H_

#include <cstddef>
#include <string>
#include <vector>

#include "tool_support.h"

namespace wavog_compare {

struct Options {
  std::string data_dir;
  std::string out_dir = "compare_output";
  std::vector<std::string> workloads = {"fr079", "csail", "lms291x4"};
  std::vector<double> resolutions = {0.05, 0.10};
  int reps = 5;
  std::size_t max_scans = 0;
  std::size_t stride_fr079 = 1;
  std::size_t stride_csail = 1;
  std::size_t timed_scans = 0;
  int synthetic_steps = 25;
  double no_return_clear = 80.0;
  int crop_cells = 200;
  bool smoke = false;
  std::string command;
};

/// The options of wavog_compare on `app` (its --help is generated from these), into `opt`.
void addOptions(CLI::App* app, Options* opt);
/// After parsing: the range checks (std::invalid_argument) and the --smoke settings.
void finishOptions(Options* opt);

}  // namespace wavog_compare

#endif  // WAVOG_MAPPING_TOOLS_COMPARE_OPTIONS_H_
