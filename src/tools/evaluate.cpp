// wavog_evaluate: runs a simulated scenario (default: the car park) through the core map under
// every update policy and compares the maps with the ground truth. Writes report.md (the table),
// summary.json and figure_data/ (final maps and a car's mean occupancy against time per policy;
// with --ndt the walls' distances of cell centres and NDT means), from which
// scripts/plot_evaluation.py draws policies.png (final maps side by side, as the paper's Fig.
// 1.2), departure.png, arrival.png (and ndt_wall_distance.png). No ROS needed to run.
#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "evaluate_output.h"
#include "tool_support.h"
#include "wavog_mapping/io/image_io.h"
#include "wavog_mapping/sim/evaluation.h"
#include "wavog_mapping/sim/laser_sim.h"
#include "wavog_mapping/sim/noise_study.h"
#include "wavog_mapping/sim/world.h"
#include "wavog_mapping/sim/world_file.h"

namespace {

namespace fs = std::filesystem;
using namespace wavog_evaluate;  // NOLINT(google-build-using-namespace): this tool's outputs
using namespace wavog::sim;      // NOLINT(google-build-using-namespace): a tool over one library

struct Options {
  std::string world_file;
  std::string out_dir = "evaluation";
  std::uint64_t seed = 1;
  double duration = -1.0;
  double resolution = 0.1;
  double fraction = 0.9;
  std::vector<std::string> policies;  // labels to keep (prefix match); empty: all
  int jobs = 2;                       // policies evaluated in parallel
  std::string offline_summary;        // JSON file embedded as "offline_map" in summary.json
  std::string core_maps;              // also map with the default forgetting config, PNGs here
  std::string pose_noise = "0:0,2:0.2,5:0.5";  // noise study levels (cm:deg); "none": skip
  bool reflection = false;                     // every run also keeps the reflection map
  bool ndt = false;                            // every run also keeps NDT cells
};

/// What --help says first.
constexpr const char* kDescription =
    "Runs a simulated scenario through every update policy and compares the maps with the "
    "ground truth: report.md, summary.json and the figures' data in figure_data/ "
    "(scripts/plot_evaluation.py draws policies.png, departure.png, arrival.png from it).";

/// The command line of wavog_evaluate (its --help is generated from these).
void addOptions(CLI::App* app, Options* o) {
  app->add_option("--world", o->world_file, "YAML/JSON world (default: the built-in car park)");
  app->add_option("--out", o->out_dir, "output folder (created)")->capture_default_str();
  wavog_tools::addInteger(app, "--seed", &o->seed, 0, "noise seed (as wavog_simulate)");
  wavog_tools::addNumber(app, "--duration", &o->duration, "simulated seconds (<= 0: the world's)");
  wavog_tools::addNumber(app, "--resolution", &o->resolution, "finest cell size (m)");
  wavog_tools::addNumber(app, "--fraction", &o->fraction,
                         "share of a car's cells that must switch, in (0, 1]");
  app->add_option("--policy", o->policies,
                  "evaluate only runs whose label starts with NAME (repeatable), e.g. --policy "
                  "forget --policy clamp")
      ->type_name("NAME");
  wavog_tools::addInteger(app, "--jobs", &o->jobs, 1,
                          "policies evaluated in parallel (1 for clean timings)");
  app->add_flag("--reflection", o->reflection,
                "every run also keeps the reflection map; the cars' mean reflection p goes into "
                "figure_data/responses.csv (plot_evaluation.py draws reflection_*.png)");
  app->add_flag("--ndt", o->ndt,
                "every run (but the pose-noise study's) also keeps normal-distribution cells; "
                "the mean distance to the true walls of the NDT means against that of the "
                "occupied cells' centres goes into the table and "
                "figure_data/ndt_wall_distance.csv (plot_evaluation.py draws "
                "ndt_wall_distance.png)");
  app->add_option("--offline-summary", o->offline_summary,
                  "embed this JSON (wavog_offline's summary) in summary.json");
  app->add_option("--core-maps", o->core_maps,
                  "also map the scenario with the default parameters (forgetting, 5 cm) through "
                  "the core and write map_s<scale>.png/.pgm/.yaml for scales 0, 2, 3, 4 there "
                  "(when wavog_offline is missing)");
  app->add_option("--pose-noise", o->pose_noise,
                  "pose-error study of none, max, clamp, forget: a list of "
                  "SIGMA_XY_CM:SIGMA_YAW_DEG levels ('none' skips it); appended to report.md, "
                  "also noise.json")
      ->capture_default_str();
}

void validate(const Options& o) {
  if (!(o.resolution > 0.0)) throw std::invalid_argument("--resolution must be > 0");
  if (!(o.fraction > 0.0 && o.fraction <= 1.0)) throw std::invalid_argument("--fraction in (0, 1]");
  if (o.pose_noise != "none") parseNoiseLevels(o.pose_noise, o.seed);  // fails early when bad
}

// The scenario mapped with the compiled defaults (the forgetting policy of config/default.yaml),
// written at several scales: what wavog_offline writes, for machines without it.
void writeCoreMaps(const World& world, const std::vector<SimScan>& scans, const std::string& dir) {
  fs::create_directories(dir);
  wavog::WaveletMap map(wavog::MapParams{});
  for (const SimScan& s : scans) {
    map.integrate(s.sensor_pose, s.view(world.vehicle.lasers[static_cast<std::size_t>(s.laser)]));
  }
  for (int scale : {0, 2, 3, 4}) {
    wavog::CellBox box;
    if (!map.bounds(scale, &box)) return;
    const wavog::Raster raster = map.exportScale(scale, box, wavog::Aggregation::kMean);
    const std::string base = (fs::path(dir) / ("map_s" + std::to_string(scale))).string();
    wavog::writePng(base + ".png", wavog::renderRgb(raster));
    wavog::writeMapServerMap(base, raster);
  }
  const wavog::MapStats stats = map.stats(true);
  wavog_tools::writeJson((fs::path(dir) / "summary.json").string(),
                         {{"tool", "wavog_evaluate --core-maps"},
                          {"scans_integrated", scans.size()},
                          {"nodes", stats.nodes},
                          {"bytes", stats.bytes},
                          {"observed_cells", stats.observed_cells}});
  std::cerr << "wavog_evaluate: default-config maps in " << dir << "/\n";
}

// The figures worth a glance, on stdout.
void printHeadline(const std::vector<WorldEvent>& events,
                   const std::vector<PolicyResult>& results) {
  std::cout << "\n" << std::left << std::setw(26) << "policy / init";
  for (const WorldEvent& e : events) {
    std::cout << std::setw(24)
              << (e.type == WorldEvent::Type::kDeparture ? "departed car free"
                                                         : "arrived car occ.");
  }
  const bool ndt = !results.empty() && results.front().params.ndt;
  std::cout << std::setw(11) << "precision" << std::setw(10) << "wall cm";
  if (ndt) std::cout << std::setw(13) << "centres cm" << std::setw(10) << "NDT cm";
  std::cout << std::setw(10) << "B/cell"
            << "us/scan\n";
  for (const PolicyResult& r : results) {
    std::cout << std::setw(26) << r.label;
    for (const EventResponse& e : r.events) std::cout << std::setw(24) << responseText(e);
    std::cout << std::setw(11) << fixed(r.precision, 3) << std::setw(10)
              << fixed(100 * r.wall_distance, 1);
    if (ndt) {
      std::cout << std::setw(13) << fixed(100 * r.ndt_walls.cell_centre_m, 2) << std::setw(10)
                << fixed(100 * r.ndt_walls.ndt_mean_m, 2);
    }
    std::cout << std::setw(10) << fixed(r.bytes_per_observed_cell, 2) << fixed(r.mean_scan_us, 0)
              << "\n";
  }
  std::cout << std::right << std::flush;
}

// A result as the same run without NDT cells would give it: the Gaussians' bytes and figures out.
PolicyResult withoutNdt(PolicyResult r) {
  if (!r.params.ndt) return r;
  r.params.ndt = false;
  r.bytes -= r.ndt_bytes;
  r.bytes_per_observed_cell =
      r.observed_cells ? static_cast<double>(r.bytes) / static_cast<double>(r.observed_cells) : 0.0;
  r.ndt_walls = NdtWallDistance();
  r.ndt_cells = 0;
  r.ndt_bytes = 0;
  return r;
}

// The pose-error study (noise_study.h) over the paper's four policies, appended to report.md.
void runPoseNoiseStudy(const World& world, const std::vector<SimScan>& scans,
                       const std::vector<WorldEvent>& events, const std::vector<PolicyRun>& runs,
                       const std::vector<PolicyResult>& results, const EvaluationOptions& eo,
                       const Options& o) {
  const std::vector<NoiseLevel> levels = parseNoiseLevels(o.pose_noise, o.seed);
  std::vector<PolicyRun> paper_runs;
  std::vector<PolicyResult> exact;  // today's results of those runs, reused for level 0
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (runs[i].params.policy.init == wavog::InitValue::kUnknown &&
        runs[i].params.policy.type != wavog::PolicyType::kClampLower) {
      // The study measures occupancy alone: with --ndt its runs keep no Gaussians, and level 0
      // (today's runs) counts its bytes without theirs (a map's other bytes do not depend on
      // them), so that every level is comparable; NDT would cost a third more time here.
      paper_runs.push_back(runs[i]);
      paper_runs.back().params.ndt = false;
      exact.push_back(withoutNdt(results[i]));
    }
  }
  if (paper_runs.empty()) return;
  std::cerr << "wavog_evaluate: pose-noise study, " << levels.size() << " levels x "
            << paper_runs.size() << " policies...\n";
  const std::vector<NoiseStudyRow> rows =
      runNoiseStudy(world, scans, events, paper_runs, levels, eo, o.jobs, &exact);
  std::ofstream(fs::path(o.out_dir) / "report.md", std::ios::app) << "\n"
                                                                  << noiseStudyMarkdown(rows);
  std::ofstream(fs::path(o.out_dir) / "noise.json") << noiseStudyJson(rows);
  std::cout << "\n"
            << std::left << std::setw(22) << "pose noise" << std::setw(26) << "policy"
            << std::setw(11) << "precision" << std::setw(10) << "wall cm" << std::setw(13)
            << "surface cm"
            << "wall width (cells)\n";
  for (const NoiseStudyRow& row : rows) {
    std::cout << std::setw(22) << row.level << std::setw(26) << row.result.label << std::setw(11)
              << fixed(row.result.precision, 3) << std::setw(10)
              << fixed(100 * row.walls.wall_distance_m, 1) << std::setw(13)
              << fixed(100 * row.walls.surface_distance_m, 1)
              << fixed(row.walls.width.mean_cells, 2) << "\n";
  }
  std::cout << std::right << std::flush;
}

int run(const Options& o) {
  validate(o);
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  World world = o.world_file.empty() ? defaultWorld() : loadWorld(o.world_file);
  if (o.duration > 0.0) world.duration = o.duration;
  fs::create_directories(o.out_dir);
  std::cerr << "wavog_evaluate: simulating '" << world.name << "' (" << world.duration
            << " s, seed " << o.seed << ")...\n";
  const std::vector<SimScan> scans = simulateAll(world, o.seed);
  const std::vector<WorldEvent> events = findEvents(world, scans, o.resolution);

  std::vector<PolicyRun> runs;
  for (const PolicyRun& r : standardPolicies(o.resolution)) {
    bool keep = o.policies.empty();
    for (const std::string& p : o.policies) keep = keep || r.label.rfind(p, 0) == 0;
    if (keep) runs.push_back(r);
  }
  for (PolicyRun& r : runs) {
    r.params.reflection = o.reflection;
    r.params.ndt = o.ndt;
  }
  if (runs.empty()) throw std::invalid_argument("no policy matches --policy");
  EvaluationOptions eo;
  eo.fraction = o.fraction;
  // Each run owns its map; the scans and events are shared read-only.
  std::vector<PolicyResult> results(runs.size());
  std::atomic<std::size_t> next{0};
  std::mutex print;
  auto worker = [&]() {
    for (std::size_t i = next++; i < runs.size(); i = next++) {
      results[i] = evaluatePolicy(world, scans, events, runs[i], eo);
      const PolicyResult& res = results[i];
      std::ostringstream line;
      line << "wavog_evaluate: " << std::setw(26) << std::left << res.label << std::right
           << fixed(res.total_s, 2) << " s, " << fixed(res.mean_scan_us, 0) << " us/scan";
      for (const EventResponse& e : res.events) line << ", " << responseText(e);
      std::lock_guard<std::mutex> lock(print);
      std::cerr << line.str() << "\n";
    }
  };
  std::vector<std::thread> threads;
  for (int j = 1; j < std::min<int>(o.jobs, static_cast<int>(runs.size())); ++j) {
    threads.emplace_back(worker);
  }
  worker();
  for (std::thread& t : threads) t.join();

  const double t_end = scans.empty() ? world.duration : scans.back().stamp;
  writeFigureData(o.out_dir, world, events, results, t_end);
  RunInfo info;
  info.seed = o.seed;
  info.resolution = o.resolution;
  info.fraction = o.fraction;
  info.jobs = o.jobs;
  info.scans = scans.size();
  info.ndt = o.ndt;
  std::ofstream(fs::path(o.out_dir) / "report.md") << report(world, info, events, results);
  const double wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  wavog_tools::writeJson((fs::path(o.out_dir) / "summary.json").string(),
                         summary(world, info, events, results, wall_s, o.offline_summary));
  std::cerr << "wavog_evaluate: wrote " << o.out_dir
            << "/{report.md, summary.json, figure_data/} in " << fixed(wall_s, 1)
            << " s; draw policies.png, departure.png and arrival.png with\n"
            << "  /usr/bin/python3 scripts/plot_evaluation.py " << o.out_dir << "\n";
  if (!o.core_maps.empty()) writeCoreMaps(world, scans, o.core_maps);
  printHeadline(events, results);
  if (o.pose_noise != "none") runPoseNoiseStudy(world, scans, events, runs, results, eo, o);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return wavog_tools::toolMain(argc, argv, "wavog_evaluate", kDescription, addOptions, run);
}
