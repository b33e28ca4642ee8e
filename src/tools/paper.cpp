// wavog_paper: the paper's figures from the Freiburg log (make paper). Maps a CARMEN log
// (default ../shared/data/fr079-corrected.log.gz) through the core with none, max, clamp and
// forget (each with MapParams::defaultsFor) and forget with the empty-bound prior, and writes to
// --out: raw scale-0 log-odds rasters (<run>_s<scale>.f32, little-endian float32, row-major from
// the bottom row, + .known.u8 and a .json sidecar), scales 2, 3, 4 of the forgetting map, and
// stats.json / report.md: bytes per observed cell, nodes, the share of observed cells at the
// policy's bounds and the wall width at half maximum across straight walls.
// scripts/paper_figures.py draws fig_1_2/1_3/1_4/1_6.png from these files. No ROS.

#include <CLI/CLI.hpp>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tool_support.h"
#include "wavog_mapping/core/params.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/io/carmen_reader.h"
#include "wavog_mapping/sim/wall_metrics.h"

namespace {

using nlohmann::json;

struct Options {
  std::string log;
  std::string out_dir = "paper_output";
  std::size_t max_scans = 0;
  int jobs = 2;
  // Zoom window (m, map frame) of Fig. 1.3 / 1.4 (b): see the default in main().
  std::vector<double> zoom;
  double bound_tolerance = 0.01;
  bool zoom_is_default = false;
  int zoom_passes = 0;  // times the robot enters the zoom window (counted from the log)
};

/// One map of the paper's figures.
struct PaperRun {
  std::string name;   // file stem
  std::string label;  // for people
  wavog::MapParams params;
};

std::vector<PaperRun> paperRuns() {
  using wavog::PolicyType;
  std::vector<PaperRun> runs;
  for (PolicyType t :
       {PolicyType::kNone, PolicyType::kMax, PolicyType::kClamp, PolicyType::kForget}) {
    runs.push_back({wavog::toString(t), wavog::toString(t), wavog::MapParams::defaultsFor(t)});
  }
  PaperRun empty{"forget_empty_bound", "forget, empty-bound prior",
                 wavog::MapParams::defaultsFor(PolicyType::kForget)};
  empty.params.policy.init = wavog::InitValue::kEmptyBound;
  runs.push_back(empty);
  return runs;
}

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

void makeDir(const std::string& dir) { std::filesystem::create_directories(dir); }

// Writes raster as <stem>.f32 / <stem>.known.u8 / <stem>.json; returns the sidecar's content.
json writeRaster(const std::string& dir, const std::string& stem, const wavog::Raster& r,
                 const PaperRun& run) {
  std::ofstream(dir + "/" + stem + ".f32", std::ios::binary)
      .write(reinterpret_cast<const char*>(r.log_odds.data()),
             static_cast<std::streamsize>(r.log_odds.size() * sizeof(float)));
  std::ofstream(dir + "/" + stem + ".known.u8", std::ios::binary)
      .write(reinterpret_cast<const char*>(r.known.data()),
             static_cast<std::streamsize>(r.known.size()));
  float lo = 0.0f, hi = 0.0f;
  std::size_t known = 0;
  for (std::size_t i = 0; i < r.log_odds.size(); ++i) {
    if (!r.known[i]) continue;
    lo = known ? std::min(lo, r.log_odds[i]) : r.log_odds[i];
    hi = known ? std::max(hi, r.log_odds[i]) : r.log_odds[i];
    ++known;
  }
  json side = {{"run", run.name},
               {"label", run.label},
               {"policy", wavog::toString(run.params.policy.type)},
               {"init", wavog::toString(run.params.policy.init)},
               {"scale", r.scale},
               {"cell_size_m", r.cell_size},
               {"origin_x_m", r.originX()},
               {"origin_y_m", r.originY()},
               {"width", r.box.width()},
               {"height", r.box.height()},
               {"cells", r.log_odds.size()},
               {"known_cells", known},
               {"min_log_odds", lo},
               {"max_log_odds", hi},
               {"prior_log_odds", run.params.initValue()},
               {"log_odds_file", stem + ".f32"},
               {"known_file", stem + ".known.u8"},
               {"layout", "float32 little-endian, row-major, row 0 = lowest y, x fastest"}};
  std::ofstream(dir + "/" + stem + ".json") << side.dump(2) << "\n";
  return side;
}

// The policy's bounds (lower, upper) in log-odds; false when it has none (policy none).
bool policyBounds(const wavog::MapParams& p, double* lo, double* hi) {
  switch (p.policy.type) {
    case wavog::PolicyType::kClamp:
      *lo = p.policy.clamp_min;
      *hi = p.policy.clamp_max;
      return true;
    case wavog::PolicyType::kForget:  // fixed points of eq. 1.6
      *lo = p.sensor.odd_emp;
      *hi = p.sensor.odd_occ;
      return true;
    case wavog::PolicyType::kMax:  // an empty reading never lowers a cell below its prior
      *lo = std::max(p.initValue(), p.sensor.odd_emp);
      *hi = p.sensor.odd_occ;
      return true;
    default:
      return false;
  }
}

int run(Options o) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  makeDir(o.out_dir);
  std::cerr << "wavog_paper: reading " << o.log << "\n";
  std::vector<wavog::CarmenScan> scans = wavog::readCarmenLog(o.log, o.max_scans);
  // ROBOTLASER1 lines repeat the FLASER laser when a log has both.
  bool has_flaser = false;
  for (const wavog::CarmenScan& s : scans) has_flaser = has_flaser || s.type == "FLASER";
  std::vector<const wavog::CarmenScan*> used;
  for (const wavog::CarmenScan& s : scans) {
    if (!(has_flaser && s.type == "ROBOTLASER1")) used.push_back(&s);
  }
  if (o.zoom_is_default) {
    bool inside = false;
    for (const wavog::CarmenScan* s : used) {
      const bool now = s->robot_pose.x > o.zoom[0] && s->robot_pose.x < o.zoom[2] &&
                       s->robot_pose.y > o.zoom[1] && s->robot_pose.y < o.zoom[3];
      o.zoom_passes += now && !inside;
      inside = now;
    }
  }
  const std::vector<PaperRun> runs = paperRuns();
  std::vector<wavog::WaveletMap> maps;
  for (const PaperRun& r : runs) maps.emplace_back(r.params);
  std::vector<double> seconds(runs.size(), 0.0);
  std::atomic<std::size_t> next{0};
  auto worker = [&]() {
    for (std::size_t i = next++; i < runs.size(); i = next++) {
      const Clock::time_point t0 = Clock::now();
      for (const wavog::CarmenScan* s : used) maps[i].integrate(s->laser_pose, s->view(0.0));
      seconds[i] = std::chrono::duration<double>(Clock::now() - t0).count();
    }
  };
  std::vector<std::thread> threads;
  for (int j = 1; j < std::min<int>(o.jobs, static_cast<int>(runs.size())); ++j) {
    threads.emplace_back(worker);
  }
  worker();
  for (std::thread& t : threads) t.join();
  std::cerr << "wavog_paper: " << used.size() << " scans mapped with " << runs.size()
            << " configurations\n";

  // One window for all: the union of the maps' bounds at scale 0 (the same data, the same area).
  wavog::CellBox window;
  bool any = false;
  for (const wavog::WaveletMap& m : maps) {
    wavog::CellBox b;
    if (!m.bounds(0, &b)) continue;
    if (!any) window = b;
    window.min_x = std::min(window.min_x, b.min_x);
    window.min_y = std::min(window.min_y, b.min_y);
    window.max_x = std::max(window.max_x, b.max_x);
    window.max_y = std::max(window.max_y, b.max_y);
    any = true;
  }
  if (!any) throw std::runtime_error(o.log + ": no scan changed the map");
  // Trim the window to the observed cells of the first map (blocks are much larger than the log).
  {
    const wavog::Raster r = maps[0].exportScale(0, window, wavog::Aggregation::kMean);
    std::int64_t x0 = r.box.width(), y0 = r.box.height(), x1 = -1, y1 = -1;
    for (std::int64_t y = 0; y < r.box.height(); ++y) {
      for (std::int64_t x = 0; x < r.box.width(); ++x) {
        if (!r.known[static_cast<std::size_t>(y * r.box.width() + x)]) continue;
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
      }
    }
    constexpr std::int64_t kPad = 16;  // a multiple of 2^4, so the coarse scales line up
    const std::int64_t ox = window.min_x, oy = window.min_y;
    window.min_x = ((ox + x0 - kPad) >> 4) << 4;
    window.min_y = ((oy + y0 - kPad) >> 4) << 4;
    window.max_x = (((ox + x1 + kPad) >> 4) + 1) << 4;
    window.max_y = (((oy + y1 + kPad) >> 4) + 1) << 4;
  }

  json stats = json::object();
  stats["log"] = o.log;
  stats["scans"] = used.size();
  stats["bound_tolerance_log_odds"] = o.bound_tolerance;
  stats["zoom_m"] = o.zoom;
  json jruns = json::array();
  std::vector<wavog::Raster> finest;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    finest.push_back(maps[i].exportScale(0, window, wavog::Aggregation::kMean));
  }
  // Wall profiles where the additive map (policy none, the first run) has straight walls.
  wavog::sim::WallProfileOptions wall_options;
  wall_options.inside_m = 0.6;
  wall_options.outside_m = 0.6;
  const std::vector<wavog::sim::WallSample> walls =
      wavog::sim::wallSamplesFromMap(finest[0], wall_options);
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const PaperRun& r = runs[i];
    const wavog::Raster& raster = finest[i];
    json jr;
    jr["run"] = r.name;
    jr["label"] = r.label;
    jr["policy"] = wavog::toString(r.params.policy.type);
    jr["init"] = wavog::toString(r.params.policy.init);
    jr["odd_occ"] = r.params.sensor.odd_occ;
    jr["odd_emp"] = r.params.sensor.odd_emp;
    jr["integration_s"] = seconds[i];
    jr["rasters"] = json::array({writeRaster(o.out_dir, r.name + "_s0", raster, r)});
    const wavog::MapStats ms = maps[i].stats(true);
    jr["nodes"] = ms.nodes;
    jr["bytes"] = ms.bytes;
    jr["observed_cells"] = ms.observed_cells;
    jr["bytes_per_observed_cell"] =
        ms.observed_cells ? static_cast<double>(ms.bytes) / static_cast<double>(ms.observed_cells)
                          : 0.0;
    double lo = 0, hi = 0;
    if (policyBounds(r.params, &lo, &hi)) {
      std::size_t known = 0, at_lo = 0, at_hi = 0;
      for (std::size_t k = 0; k < raster.log_odds.size(); ++k) {
        if (!raster.known[k]) continue;
        ++known;
        at_lo += std::abs(raster.log_odds[k] - lo) <= o.bound_tolerance;
        at_hi += std::abs(raster.log_odds[k] - hi) <= o.bound_tolerance;
      }
      jr["bounds"] = {lo, hi};
      jr["share_at_lower_bound"] = known ? static_cast<double>(at_lo) / known : 0.0;
      jr["share_at_upper_bound"] = known ? static_cast<double>(at_hi) / known : 0.0;
    } else {
      jr["bounds"] = nullptr;
    }
    const wavog::sim::WallWidth ww = wavog::sim::wallWidthAtHalfMax(raster, walls, wall_options);
    jr["wall_width_mean_cells"] = ww.mean_cells;
    jr["wall_width_median_cells"] = ww.median_cells;
    jr["wall_profiles_measured"] = ww.measured;
    jr["wall_profiles"] = ww.samples;
    if (r.params.policy.type == wavog::PolicyType::kForget &&
        r.params.policy.init == wavog::InitValue::kUnknown) {
      json scales = json::array();
      for (int s : {0, 2, 3, 4}) {
        const wavog::CellBox b{window.min_x >> s, window.min_y >> s, window.max_x >> s,
                               window.max_y >> s};
        const wavog::Raster rs = maps[i].exportScale(s, b, wavog::Aggregation::kMean);
        scales.push_back(s == 0 ? jr["rasters"][0]
                                : writeRaster(o.out_dir, r.name + "_s" + std::to_string(s), rs, r));
      }
      jr["rasters"] = scales;
    }
    jruns.push_back(jr);
  }
  stats["runs"] = jruns;
  stats["wall_samples"] = walls.size();
  stats["wall_width_method"] =
      "P(occ) profiles across straight walls found in the 'none' map (occupied cells whose "
      "occupied neighbours within 0.4 m lie on a line, second-moment ratio >= 25, one per 0.5 m "
      "square), +-0.6 m along the normal at the cell size; width = observed cells at or above "
      "half height between the lowest value and the peak (within 0.25 m of the wall)";
  stats["wall_time_s"] = std::chrono::duration<double>(Clock::now() - start).count();
  std::ofstream(o.out_dir + "/stats.json") << stats.dump(2) << "\n";

  // report.md: the table, for people.
  std::ostringstream md;
  md << "# The paper's figures from the Freiburg log\n\n"
     << "Log: `" << o.log << "`, " << used.size() << " scans, each map with its documented "
     << "defaults (`MapParams::defaultsFor`: 5 cm cells; forget odd_occ 3.5 / odd_emp -2 / "
     << "gamma 0.3; the others 0.85 / -0.4, clamp [-2, 3.5]).\n\n"
     << "| map | bytes / observed cell | nodes | observed cells | at lower bound | at upper bound "
        "| wall width at half max (cells, mean / median) |\n|---|---|---|---|---|---|---|\n";
  for (const json& jr : jruns) {
    md << "| " << jr["label"].get<std::string>() << " | "
       << fixed(jr["bytes_per_observed_cell"].get<double>(), 2) << " | "
       << jr["nodes"].get<std::size_t>() << " | " << jr["observed_cells"].get<std::size_t>()
       << " | ";
    if (jr["bounds"].is_null()) {
      md << "no bounds | no bounds | ";
    } else {
      md << fixed(100 * jr["share_at_lower_bound"].get<double>(), 1) << " % | "
         << fixed(100 * jr["share_at_upper_bound"].get<double>(), 1) << " % | ";
    }
    md << fixed(jr["wall_width_mean_cells"].get<double>(), 2) << " / "
       << fixed(jr["wall_width_median_cells"].get<double>(), 1) << " |\n";
  }
  md << "\n- *at lower / upper bound*: share of the observed cells within " << o.bound_tolerance
     << " log-odds of the policy's bounds: clamp [clamp_min, clamp_max], "
     << "forget the fixed points [odd_emp, odd_occ], max [prior, odd_occ] (an empty reading "
     << "never lowers a cell below its prior); none has no bounds.\n"
     << "- *wall width*: " << stats["wall_width_method"].get<std::string>() << "; " << walls.size()
     << " profiles. One cell is ideal.\n"
     << "- *bytes / observed cell*: `WaveletMap::stats().bytes` over the cells ever observed; a "
     << "dense float grid costs 4.\n\n"
     << "Zoom of Fig. 1.3 and 1.4 (b): x " << o.zoom[0] << " .. " << o.zoom[2] << " m, y "
     << o.zoom[1] << " .. " << o.zoom[3] << " m (map frame)";
  if (o.zoom_is_default) {
    md << ": the middle of the main corridor, with both corridor walls and the doorways of "
       << "the rooms beside it; the robot drives through this window " << o.zoom_passes
       << " times and looks into it from the rooms, so its walls are seen "
       << "from many vantage points";
  }
  md << ".\n\n"
     << "![Fig. 1.2](fig_1_2.png)\n\n![Fig. 1.3](fig_1_3.png)\n\n![Fig. 1.4](fig_1_4.png)\n\n"
     << "![Fig. 1.6](fig_1_6.png)\n\n"
     << "Made by `make paper`, i.e. `wavog_paper --out DIR " << o.log << "` then "
     << "`/usr/bin/python3 scripts/paper_figures.py DIR`. The rasters behind the figures are in "
     << "DIR (`<map>_s<scale>.f32` float32 log-odds, `.known.u8`, `.json` sidecar).\n";
  std::ofstream(o.out_dir + "/report.md") << md.str();
  std::cerr << "wavog_paper: wrote " << o.out_dir << "/{stats.json, report.md, *.f32} in "
            << fixed(stats["wall_time_s"].get<double>(), 1) << " s\n";
  std::cout << md.str();
  return 0;
}

/// The command line of wavog_paper (its --help is generated from these).
void addOptions(CLI::App* app, Options* o) {
  app->add_option("log", o->log, "CARMEN log (default: fr079-corrected.log.gz in the data dir)");
  app->add_option("-o,--out", o->out_dir, "output folder")->capture_default_str();
  wavog_tools::addInteger(app, "--max-scans", &o->max_scans, 0,
                          "map only the first N scans (0: all)");
  wavog_tools::addInteger(app, "-j,--jobs", &o->jobs, 1, "maps built in parallel (at most 16)");
  app->add_option_function<std::vector<std::string>>(
         "--zoom",
         [o](const std::vector<std::string>& v) {
           o->zoom.clear();
           for (const std::string& x : v)
             o->zoom.push_back(wavog_tools::parseNumber("--zoom", x.c_str()));
         },
         "zoom window of fig_1_3 / fig_1_4 (m): X0 Y0 X1 Y1")
      ->expected(4)
      ->type_name("NUM");
  wavog_tools::addNumber(
      app, "--bound-tolerance", &o->bound_tolerance,
      "a cell this close (log-odds, in [0, 1]) to a bound counts as at the bound");
}

/// The defaults that depend on the machine (the data directory) and the range checks.
void finishOptions(Options* o) {
  if (o->jobs > 16) throw std::invalid_argument("--jobs must be in [1, 16]");
  if (!(o->bound_tolerance >= 0.0 && o->bound_tolerance <= 1.0)) {
    throw std::invalid_argument("--bound-tolerance must be in [0, 1]");
  }
  if (o->log.empty()) {
    const std::string dir = wavog::findDataDir();
    if (dir.empty()) throw std::runtime_error("no data directory found; set WAVOG_DATA_DIR");
    o->log = (std::filesystem::path(dir) / "fr079-corrected.log.gz").string();
  }
  if (o->zoom.empty()) {
    o->zoom = {-5.0, -3.0, 5.0, 3.0};
    o->zoom_is_default = true;
  }
  if (!(o->zoom[0] < o->zoom[2] && o->zoom[1] < o->zoom[3])) {
    throw std::invalid_argument("--zoom: X0 < X1 and Y0 < Y1 required");
  }
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{wavog_tools::wrapText(
                   "Maps a CARMEN log with the paper's policies and exports the rasters and "
                   "figures of merit behind fig_1_2/1_3/1_4/1_6 (scripts/paper_figures.py).",
                   wavog_tools::kHelpWidth),
               "wavog_paper"};
  addOptions(&app, &o);
  return wavog_tools::runTool(&app, argc, argv, [&] {
    finishOptions(&o);
    return run(o);
  });
}
