// wavog_evaluate: runs a simulated scenario (default: the car park) through the core map under
// every update policy and compares the maps with the ground truth. Writes report.md (the table),
// policies.png (final maps side by side, as the paper's Fig. 1.2), departure.png and arrival.png
// (a car's mean occupancy against time per policy) and summary.json. No ROS needed to run.
#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "plot.h"
#include "tool_support.h"
#include "wavog_mapping/io/image_io.h"
#include "wavog_mapping/sim/evaluation.h"
#include "wavog_mapping/sim/laser_sim.h"
#include "wavog_mapping/sim/noise_study.h"
#include "wavog_mapping/sim/world.h"
#include "wavog_mapping/sim/world_file.h"

namespace {

using wavog_tools::parseNumber;

using wavog::Image;
using wavog::Rgb;
using namespace wavog::sim;  // NOLINT(google-build-using-namespace): a tool over one library

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
};

void usage(std::ostream& out) {
  out << "usage: wavog_evaluate [options]\n"
         "Runs a simulated scenario through every update policy and compares with ground truth.\n\n"
         "  --world FILE          YAML/JSON world (default: the built-in car park)\n"
         "  --out DIR             output folder (default ./evaluation)\n"
         "  --seed N              noise seed (default 1, as wavog_simulate)\n"
         "  --duration S          simulated seconds (default: the world's)\n"
         "  --resolution R        finest cell size (m, default 0.1)\n"
         "  --fraction F          share of a car's cells that must switch (default 0.9)\n"
         "  --policy NAME         evaluate only runs whose label starts with NAME (repeatable),\n"
         "                        e.g. --policy forget --policy clamp\n"
         "  --jobs N              policies evaluated in parallel (default 2; 1 for clean timings)\n"
         "  --offline-summary F   embed this JSON (wavog_offline's summary) in summary.json\n"
         "  --core-maps DIR       also map the scenario with the default parameters (forgetting,\n"
         "                        5 cm) through the core and write map_s<scale>.png/.pgm/.yaml\n"
         "                        for scales 0, 2, 3, 4 there (when wavog_offline is missing)\n"
         "  --pose-noise LEVELS   pose-error study of none, max, clamp, forget: a list of\n"
         "                        SIGMA_XY_CM:SIGMA_YAW_DEG levels (default 0:0,2:0.2,5:0.5;\n"
         "                        'none' skips it); appended to report.md, also noise.json\n";
}

Options parseArgs(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      usage(std::cout);
      std::exit(0);
    }
    if (i + 1 >= argc) throw std::invalid_argument("unknown option or missing value: " + a);
    const char* v = argv[++i];
    if (a == "--world")
      o.world_file = v;
    else if (a == "--out")
      o.out_dir = v;
    else if (a == "--seed")
      o.seed = static_cast<std::uint64_t>(parseNumber(a, v));
    else if (a == "--duration")
      o.duration = parseNumber(a, v);
    else if (a == "--resolution")
      o.resolution = parseNumber(a, v);
    else if (a == "--fraction")
      o.fraction = parseNumber(a, v);
    else if (a == "--policy")
      o.policies.push_back(v);
    else if (a == "--offline-summary")
      o.offline_summary = v;
    else if (a == "--core-maps")
      o.core_maps = v;
    else if (a == "--pose-noise")
      o.pose_noise = v;
    else if (a == "--jobs")
      o.jobs = static_cast<int>(parseNumber(a, v));
    else
      throw std::invalid_argument("unknown option: " + a);
  }
  if (o.jobs < 1) throw std::invalid_argument("--jobs must be >= 1");
  if (!(o.resolution > 0.0)) throw std::invalid_argument("--resolution must be > 0");
  if (!(o.fraction > 0.0 && o.fraction <= 1.0)) throw std::invalid_argument("--fraction in (0, 1]");
  if (o.pose_noise != "none") parseNoiseLevels(o.pose_noise, o.seed);  // fails early when bad
  return o;
}

// ---- Formatting ---------------------------------------------------------------------------

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

std::string responseText(const EventResponse& r) {
  if (!r.reached()) return "never";
  return fixed(r.seconds, 2) + " s (" + std::to_string(r.scans) + " scans)";
}

std::string jsonEscape(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string jsonNumber(double v) {
  if (!std::isfinite(v)) return "null";
  std::ostringstream s;
  s << std::setprecision(6) << v;
  return s.str();
}

// ---- Pictures -----------------------------------------------------------------------------

const Rgb kBlack{0, 0, 0};
const Rgb kGrey{150, 150, 150};
// One colour per run, distinguishable on white.
const Rgb kPalette[] = {{0, 0, 0},      {230, 159, 0}, {160, 110, 0},  {86, 180, 233},
                        {0, 90, 160},   {0, 158, 115}, {0, 100, 60},   {204, 121, 167},
                        {150, 50, 110}, {213, 94, 0},  {120, 120, 120}};
Rgb colourOf(std::size_t i) { return kPalette[i % (sizeof(kPalette) / sizeof(kPalette[0]))]; }

// A raster halved in each direction: known if any child is, value the largest known child
// (thin walls stay visible in a small picture).
wavog::Raster halve(const wavog::Raster& in) {
  wavog::Raster out;
  out.scale = in.scale + 1;
  out.cell_size = in.cell_size * 2;
  const int w = static_cast<int>(in.box.width());
  const int h = static_cast<int>(in.box.height());
  const int ow = (w + 1) / 2;
  const int oh = (h + 1) / 2;
  out.box = wavog::CellBox{0, 0, ow, oh};
  out.log_odds.assign(static_cast<std::size_t>(ow) * oh, 0.0f);
  out.known.assign(out.log_odds.size(), 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const std::size_t o = static_cast<std::size_t>(y / 2) * ow + x / 2;
      if (!in.known[i]) continue;
      out.log_odds[o] = out.known[o] ? std::max(out.log_odds[o], in.log_odds[i]) : in.log_odds[i];
      out.known[o] = 1;
    }
  }
  return out;
}

Image sideBySide(const std::vector<PolicyResult>& results, const std::string& title) {
  constexpr int kColumns = 3;
  constexpr int kGap = 8;
  constexpr int kLabel = 18;
  constexpr int kTitle = 24;
  std::vector<Image> panels;
  for (const PolicyResult& r : results) panels.push_back(wavog::renderRgb(halve(r.final_map)));
  const int pw = panels.empty() ? 0 : panels[0].width;
  const int ph = panels.empty() ? 0 : panels[0].height;
  const int rows = (static_cast<int>(panels.size()) + kColumns - 1) / kColumns;
  Image img(kColumns * (pw + kGap) + kGap, kTitle + rows * (ph + kLabel + kGap) + kGap, 3);
  std::fill(img.pixels.begin(), img.pixels.end(), 255);
  drawText(&img, kGap, 6, title, kBlack, 2);
  for (std::size_t i = 0; i < panels.size(); ++i) {
    const int x0 = kGap + static_cast<int>(i % kColumns) * (pw + kGap);
    const int y0 = kTitle + static_cast<int>(i / kColumns) * (ph + kLabel + kGap);
    drawText(&img, x0, y0 + 3, results[i].label, kBlack, 2);
    for (int y = 0; y < ph; ++y) {
      for (int x = 0; x < pw; ++x) {
        const std::uint8_t* p = panels[i].at(x, y);
        putPixel(&img, x0 + x, y0 + kLabel + y, Rgb{p[0], p[1], p[2]});
      }
    }
  }
  return img;
}

Image plotEvent(const WorldEvent& event, std::size_t k, const std::vector<PolicyResult>& results,
                double t_end) {
  constexpr int kW = 1010, kH = 440;
  constexpr int kLeft = 60, kRight = 260, kTop = 34, kBottom = 40;
  Image img(kW, kH, 3);
  std::fill(img.pixels.begin(), img.pixels.end(), 255);
  const double t0 = std::max(0.0, event.start_time - 2.0);
  const int pw = kW - kLeft - kRight;
  const int ph = kH - kTop - kBottom;
  auto px = [&](double t) {
    return kLeft + static_cast<int>(std::lround((t - t0) / (t_end - t0) * pw));
  };
  auto py = [&](double p) { return kTop + static_cast<int>(std::lround((1.0 - p) * ph)); };
  const bool departure = event.type == WorldEvent::Type::kDeparture;
  drawText(&img, kLeft, 8,
           std::string(departure ? "departed car " : "arrived car ") + event.name +
               ": mean p(occ) of its " + std::to_string(event.cells.size()) + " cells",
           kBlack, 2);
  // Axes, the 0.5 line and the event time.
  drawLine(&img, kLeft, kTop, kLeft, kTop + ph, kBlack);
  drawLine(&img, kLeft, kTop + ph, kLeft + pw, kTop + ph, kBlack);
  drawLine(&img, kLeft, py(0.5), kLeft + pw, py(0.5), kGrey, 1, 4);
  drawLine(&img, px(event.event_time), kTop, px(event.event_time), kTop + ph, kGrey, 1, 4);
  drawText(&img, px(event.event_time) + 4, kTop + 2, departure ? "stall clear" : "parked", kGrey,
           2);
  for (int tick = 0; tick <= 4; ++tick) {
    const double p = 0.25 * tick;
    drawLine(&img, kLeft - 5, py(p), kLeft, py(p), kBlack);
    drawText(&img, 8, py(p) - 5, fixed(p, 2), kBlack, 2);
  }
  const double step = (t_end - t0) > 40 ? 10.0 : (t_end - t0) > 10 ? 5.0 : 1.0;
  const auto first_tick = static_cast<int>(std::ceil(t0 / step));
  for (int tick = first_tick; tick * step <= t_end + 1e-9; ++tick) {
    const double t = tick * step;
    drawLine(&img, px(t), kTop + ph, px(t), kTop + ph + 5, kBlack);
    const std::string label = fixed(t, 0);
    drawText(&img, px(t) - textWidth(label) / 2, kTop + ph + 9, label, kBlack, 2);
  }
  drawText(&img, kLeft + pw - textWidth("time (s)"), kTop + ph + 24, "time (s)", kBlack, 2);
  for (std::size_t i = 0; i < results.size(); ++i) {
    const EventResponse& r = results[i].events[k];
    for (std::size_t j = 1; j < r.times.size(); ++j) {
      drawLine(&img, px(r.times[j - 1]), py(r.mean_occupancy[j - 1]), px(r.times[j]),
               py(r.mean_occupancy[j]), colourOf(i), 2);
    }
    const int ly = kTop + 4 + static_cast<int>(i) * 16;
    fillRect(&img, kLeft + pw + 12, ly + 2, kLeft + pw + 30, ly + 6, colourOf(i));
    drawText(&img, kLeft + pw + 36, ly, results[i].label, kBlack, 2);
  }
  return img;
}

// ---- Report ------------------------------------------------------------------------------

std::string report(const World& world, const Options& o, std::size_t scan_count,
                   const std::vector<WorldEvent>& events,
                   const std::vector<PolicyResult>& results) {
  std::ostringstream md;
  const LaserParams& l = world.vehicle.lasers.front();
  md << "# Update policies on the simulated scenario '" << world.name << "'\n\n"
     << "Scenario: " << fixed(world.duration, 0) << " s, " << world.vehicle.lasers.size()
     << " lasers (" << l.beams << " beams over " << fixed(l.fov * 180 / M_PI, 0) << " deg, "
     << fixed(l.range_max, 0) << " m, " << fixed(l.rate_hz, 0) << " Hz each, range noise sigma "
     << fixed(l.noise_sigma, 3) << " m, dropouts " << fixed(100 * l.dropout_prob, 1) << " %), "
     << scan_count << " scans, seed " << o.seed << ". Map: resolution " << fixed(o.resolution, 2)
     << " m, each policy with its documented defaults "
     << "(`MapParams::defaultsFor`: forget odd_occ 3.5 / odd_emp -2 / gamma 0.3; the others "
     << "0.85 / -0.4, clamp [-2, 3.5]).\n\n";
  md << "Events:\n";
  for (const WorldEvent& e : events) {
    if (e.type == WorldEvent::Type::kDeparture) {
      md << "- `" << e.name << "` leaves its stall at t = " << fixed(e.start_time, 1)
         << " s; the stall is clear at t = " << fixed(e.event_time, 2) << " s. " << e.cells.size()
         << " cells saw it while parked.\n";
    } else {
      md << "- `" << e.name << "` enters at t = " << fixed(e.start_time, 1)
         << " s and is parked at t = " << fixed(e.event_time, 2) << " s. " << e.cells.size()
         << " cells saw it once parked.\n";
    }
  }
  md << "\n| policy / init |";
  for (const WorldEvent& e : events) {
    md << (e.type == WorldEvent::Type::kDeparture ? " departed car free after |"
                                                  : " arrived car occupied after |");
  }
  md << " occupied precision | recall | wall distance (cm) | nodes | bytes / observed cell |"
        " us / scan (mean, max) |\n|---|";
  for (std::size_t k = 0; k < events.size(); ++k) md << "---|";
  md << "---|---|---|---|---|---|\n";
  for (const PolicyResult& r : results) {
    md << "| " << r.label << " |";
    for (const EventResponse& e : r.events) md << " " << responseText(e) << " |";
    md << " " << fixed(r.precision, 3) << " | " << fixed(r.recall, 3) << " | "
       << fixed(100 * r.wall_distance, 1) << " | " << r.nodes << " | "
       << fixed(r.bytes_per_observed_cell, 2) << " | " << fixed(r.mean_scan_us, 0) << ", "
       << fixed(r.max_scan_us, 0) << " |\n";
  }
  md << "\nDefinitions (all against the simulator's ground truth, `include/wavog_mapping/sim/`):\n"
     << "- *free after* / *occupied after*: per cell of the car, the delay (seconds, and scans of "
     << "all lasers counting the first) from the first scan that truly sees the cell after the "
     << "event (free after a departure, hit after an arrival) until the map has P(occ) < 0.5 "
     << "(departure) or > 0.5 (arrival); the table gives the " << fixed(100 * o.fraction, 0)
     << " % quantile over the cells. A car's cells are those holding at least 2 true beam hits "
     << "on it while parked. *never*: not within the scenario. The plots show the mean P(occ) "
     << "of the same cells, which also waits for the truck to come back where it sees them.\n"
     << "- *occupied precision*: share of the final map's occupied cells (log-odds > 0.001) within "
        "one "
     << "cell of a true surface at the end; *recall*: share of the observed true-surface cells "
     << "within one cell of an occupied one.\n"
     << "- *wall distance*: mean distance from occupied cells nearest to a wall (within 1 m) to "
     << "the wall's cells; about half a cell is ideal, more means thick walls.\n"
     << "- *bytes / observed cell*: `WaveletMap::stats().bytes` over the cells ever observed; "
     << "a dense float grid costs 4. *us / scan*: `integrate()` wall time on this machine ("
     << o.jobs << " policies run in parallel).\n\n"
     << "![final maps](policies.png)\n\n![departed car](departure.png)\n\n"
     << "![arrived car](arrival.png)\n";
  return md.str();
}

std::string json(const World& world, const Options& o, std::size_t scan_count,
                 const std::vector<WorldEvent>& events, const std::vector<PolicyResult>& results,
                 double wall_s) {
  std::ostringstream js;
  js << "{\n  \"world\": " << jsonEscape(world.name)
     << ",\n  \"duration_s\": " << jsonNumber(world.duration) << ",\n  \"seed\": " << o.seed
     << ",\n  \"scans\": " << scan_count << ",\n  \"resolution\": " << jsonNumber(o.resolution)
     << ",\n  \"evaluation_wall_time_s\": " << jsonNumber(wall_s) << ",\n  \"events\": [";
  for (std::size_t k = 0; k < events.size(); ++k) {
    const WorldEvent& e = events[k];
    js << (k ? "," : "") << "\n    {\"name\": " << jsonEscape(e.name) << ", \"type\": "
       << (e.type == WorldEvent::Type::kDeparture ? "\"departure\"" : "\"arrival\"")
       << ", \"start_s\": " << jsonNumber(e.start_time)
       << ", \"event_s\": " << jsonNumber(e.event_time) << ", \"cells\": " << e.cells.size() << "}";
  }
  js << "\n  ],\n  \"policies\": [";
  for (std::size_t i = 0; i < results.size(); ++i) {
    const PolicyResult& r = results[i];
    js << (i ? "," : "") << "\n    {\"label\": " << jsonEscape(r.label)
       << ", \"policy\": " << jsonEscape(wavog::toString(r.params.policy.type))
       << ", \"init\": " << jsonEscape(wavog::toString(r.params.policy.init))
       << ", \"responses\": [";
    for (std::size_t k = 0; k < r.events.size(); ++k) {
      js << (k ? ", " : "") << "{\"seconds\": " << jsonNumber(r.events[k].seconds)
         << ", \"scans\": "
         << (r.events[k].reached() ? std::to_string(r.events[k].scans) : std::string("null"))
         << "}";
    }
    js << "], \"precision\": " << jsonNumber(r.precision)
       << ", \"recall\": " << jsonNumber(r.recall)
       << ", \"wall_distance_m\": " << jsonNumber(r.wall_distance)
       << ", \"occupied_cells\": " << r.occupied_cells << ", \"nodes\": " << r.nodes
       << ", \"bytes\": " << r.bytes << ", \"observed_cells\": " << r.observed_cells
       << ", \"bytes_per_observed_cell\": " << jsonNumber(r.bytes_per_observed_cell)
       << ", \"mean_scan_us\": " << jsonNumber(r.mean_scan_us)
       << ", \"max_scan_us\": " << jsonNumber(r.max_scan_us)
       << ", \"integration_s\": " << jsonNumber(r.total_s) << "}";
  }
  js << "\n  ]";
  if (!o.offline_summary.empty()) {
    std::ifstream in(o.offline_summary);
    std::stringstream buffer;
    buffer << in.rdbuf();
    std::string text = buffer.str();
    while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) text.pop_back();
    js << ",\n  \"offline_map\": " << (text.empty() ? "null" : text);
  }
  js << "\n}\n";
  return js.str();
}

// The scenario mapped with the compiled defaults (the forgetting policy of config/default.yaml),
// written at several scales: what wavog_offline writes, for machines without it.
void writeCoreMaps(const World& world, const std::vector<SimScan>& scans, const std::string& dir) {
  if (mkdir(dir.c_str(), 0755) != 0 && errno != EEXIST) {
    throw std::runtime_error(dir + ": cannot create directory");
  }
  wavog::WaveletMap map(wavog::MapParams{});
  for (const SimScan& s : scans) {
    map.integrate(s.sensor_pose, s.view(world.vehicle.lasers[static_cast<std::size_t>(s.laser)]));
  }
  for (int scale : {0, 2, 3, 4}) {
    wavog::CellBox box;
    if (!map.bounds(scale, &box)) return;
    const wavog::Raster raster = map.exportScale(scale, box, wavog::Aggregation::kMean);
    const std::string base = dir + "/map_s" + std::to_string(scale);
    wavog::writePng(base + ".png", wavog::renderRgb(raster));
    wavog::writeMapServerMap(base, raster);
  }
  const wavog::MapStats stats = map.stats(true);
  std::ofstream(dir + "/summary.json")
      << "{\"tool\": \"wavog_evaluate --core-maps\", \"scans_integrated\": " << scans.size()
      << ", \"nodes\": " << stats.nodes << ", \"bytes\": " << stats.bytes
      << ", \"observed_cells\": " << stats.observed_cells << "}\n";
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
  std::cout << std::setw(11) << "precision" << std::setw(10) << "wall cm" << std::setw(10)
            << "B/cell"
            << "us/scan\n";
  for (const PolicyResult& r : results) {
    std::cout << std::setw(26) << r.label;
    for (const EventResponse& e : r.events) std::cout << std::setw(24) << responseText(e);
    std::cout << std::setw(11) << fixed(r.precision, 3) << std::setw(10)
              << fixed(100 * r.wall_distance, 1) << std::setw(10)
              << fixed(r.bytes_per_observed_cell, 2) << fixed(r.mean_scan_us, 0) << "\n";
  }
  std::cout << std::right << std::flush;
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
      paper_runs.push_back(runs[i]);
      exact.push_back(results[i]);
    }
  }
  if (paper_runs.empty()) return;
  std::cerr << "wavog_evaluate: pose-noise study, " << levels.size() << " levels x "
            << paper_runs.size() << " policies...\n";
  const std::vector<NoiseStudyRow> rows =
      runNoiseStudy(world, scans, events, paper_runs, levels, eo, o.jobs, &exact);
  std::ofstream(o.out_dir + "/report.md", std::ios::app) << "\n" << noiseStudyMarkdown(rows);
  std::ofstream(o.out_dir + "/noise.json") << noiseStudyJson(rows);
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
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  World world = o.world_file.empty() ? defaultWorld() : loadWorld(o.world_file);
  if (o.duration > 0.0) world.duration = o.duration;
  if (mkdir(o.out_dir.c_str(), 0755) != 0 && errno != EEXIST) {
    throw std::runtime_error(o.out_dir + ": cannot create directory");
  }
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
  wavog::writePng(o.out_dir + "/policies.png",
                  sideBySide(results, "final maps at t = " + fixed(t_end, 0) + " s, " + world.name +
                                          " (pale blue: never observed)"));
  for (std::size_t k = 0; k < events.size(); ++k) {
    const bool departure = events[k].type == WorldEvent::Type::kDeparture;
    // The first departure and the first arrival get the fixed names the report links to.
    std::string name = departure ? "departure" : "arrival";
    for (std::size_t j = 0; j < k; ++j) {
      if (events[j].type == events[k].type) name += "_" + std::to_string(k);
    }
    wavog::writePng(o.out_dir + "/" + name + ".png", plotEvent(events[k], k, results, t_end));
  }
  std::ofstream(o.out_dir + "/report.md") << report(world, o, scans.size(), events, results);
  const double wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  std::ofstream(o.out_dir + "/summary.json")
      << json(world, o, scans.size(), events, results, wall_s);
  std::cerr << "wavog_evaluate: wrote " << o.out_dir << "/{report.md, policies.png, "
            << "departure.png, arrival.png, summary.json} in " << fixed(wall_s, 1) << " s\n";
  if (!o.core_maps.empty()) writeCoreMaps(world, scans, o.core_maps);
  printHeadline(events, results);
  if (o.pose_noise != "none") runPoseNoiseStudy(world, scans, events, runs, results, eo, o);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parseArgs(argc, argv));
  } catch (const std::invalid_argument& e) {
    std::cerr << "wavog_evaluate: " << e.what() << "\n";
    usage(std::cerr);
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "wavog_evaluate: " << e.what() << "\n";
    return 1;
  }
}
