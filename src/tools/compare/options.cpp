#include "compare/options.h"

#include <stdexcept>

namespace wavog_compare {
namespace {

/// "fr079=N,csail=N" into the two strides.
void parseStrides(const std::string& text, Options* opt) {
  for (const std::string& item : wavog_tools::splitList(text)) {
    const std::size_t eq = item.find('=');
    const std::string key = item.substr(0, eq);
    const std::size_t n = eq == std::string::npos
                              ? 0
                              : static_cast<std::size_t>(wavog_tools::parseInteger(
                                    "--stride", item.substr(eq + 1).c_str(), 1));
    if (n == 0 || (key != "fr079" && key != "csail")) {
      throw std::invalid_argument("--stride takes fr079=N,csail=N with N >= 1");
    }
    (key == "fr079" ? opt->stride_fr079 : opt->stride_csail) = n;
  }
}

}  // namespace

void addOptions(CLI::App* app, Options* opt) {
  app->add_option_function<std::string>(
      "--workloads", [opt](const std::string& v) { opt->workloads = wavog_tools::splitList(v); },
      "fr079,csail,lms291x4 (default: all three)");
  app->add_option_function<std::string>(
      "--resolutions",
      [opt](const std::string& v) {
        opt->resolutions.clear();
        for (const std::string& r : wavog_tools::splitList(v)) {
          opt->resolutions.push_back(wavog_tools::parseNumber("--resolutions", r.c_str()));
        }
      },
      "cell sizes in m, comma-separated (default 0.05,0.1)");
  wavog_tools::addInteger(app, "--reps", &opt->reps, 1, "timed repetitions after the warm-up");
  wavog_tools::addInteger(app, "--max-scans", &opt->max_scans, 0,
                          "scans taken from each log, 0 = all");
  app->add_option_function<std::string>(
      "--stride", [opt](const std::string& v) { parseStrides(v, opt); },
      "take every N-th scan of a log, e.g. fr079=8,csail=14 (default 1)");
  wavog_tools::addInteger(app, "--timed-scans", &opt->timed_scans, 0,
                          "scans per timed repetition (a prefix), 0 = all");
  wavog_tools::addInteger(app, "--synthetic-steps", &opt->synthetic_steps, 1,
                          "steps of the four-LMS-291 workload, 4 scans each");
  wavog_tools::addNumber(app, "--no-return-clear", &opt->no_return_clear,
                         "no-return beams clear free space up to M metres, 0 = not at all "
                         "(OctoMap's maxrange)");
  wavog_tools::addInteger(app, "--crop", &opt->crop_cells, 8,
                          "cells per side of the zoomed disagreement pictures");
  app->add_option("--data", opt->data_dir,
                  "directory of the CARMEN logs (default: found from ../shared/data)");
  app->add_option("--out", opt->out_dir, "output directory")->capture_default_str();
  app->add_flag("--smoke", opt->smoke, "tiny workload, 1 repetition: a test that the program runs");
}

void finishOptions(Options* opt) {
  if (opt->no_return_clear < 0) throw std::invalid_argument("--no-return-clear must be >= 0");
  if (opt->smoke) {
    opt->reps = 1;
    opt->resolutions = {0.2};
    opt->synthetic_steps = 1;
    opt->max_scans = 10;
    opt->crop_cells = 32;
  }
}

}  // namespace wavog_compare
