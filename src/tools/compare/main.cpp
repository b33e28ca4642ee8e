// wavog_compare: wavog_core (clamping and forgetting), OctoMap (OcTree::insertPointCloud) and the
// dense baseline grid, side by side in one process, on the same scans at the same resolution:
// speed (median scans/s over repetitions after a warm-up), memory (own account and resident-set
// growth, bytes per observed cell) and map agreement over the commonly observed cells, plus PNGs
// colouring the disagreeing cells. Single-threaded; run by `make compare` (issue 6). The parts:
// options.h (command line), workloads.h (scans), subjects.h (the structures), measure.h (the
// runs), report.h (results.md, results.csv).
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "compare/measure.h"
#include "compare/options.h"
#include "compare/report.h"
#include "compare/workloads.h"
#include "tool_support.h"
#include "wavog_mapping/io/carmen_reader.h"

#ifndef WAVOG_SOURCE_DIR
#define WAVOG_SOURCE_DIR "."
#endif

namespace {

int run(wavog_compare::Options* opt) {
  wavog_compare::finishOptions(opt);
  if (opt->data_dir.empty()) opt->data_dir = wavog::findDataDir(WAVOG_SOURCE_DIR);
  std::filesystem::create_directories(opt->out_dir);
  std::vector<wavog_compare::WorkloadResult> results;
  wavog_compare::forEachWorkload(*opt, [&](const wavog_compare::Workload& wl) {
    results.push_back(wavog_compare::runWorkload(wl, *opt));
  });
  if (results.empty()) throw std::runtime_error("no workload ran");
  const std::string text = wavog_compare::report(results, *opt);
  std::cout << text;
  wavog_compare::writeResults(results, *opt, text);
  std::cerr << "wrote " << opt->out_dir << "/results.md, results.csv and the disagreement PNGs\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  wavog_compare::Options opt;
  for (int i = 0; i < argc; ++i) opt.command += (i ? " " : "") + std::string(argv[i]);
  CLI::App app{
      wavog_tools::wrapText(
          "Runs wavog_core (clamping and forgetting), OctoMap and the dense baseline grid side "
          "by side on the same scans: speed, memory, map agreement; writes results.md, "
          "results.csv and the disagreement PNGs to --out.",
          wavog_tools::kHelpWidth),
      "wavog_compare"};
  wavog_compare::addOptions(&app, &opt);
  return wavog_tools::runTool(&app, argc, argv, [&] { return run(&opt); });
}
