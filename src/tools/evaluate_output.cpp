#include "evaluate_output.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "wavog_mapping/io/image_io.h"

namespace wavog_evaluate {

using Json = nlohmann::ordered_json;
using namespace wavog::sim;  // NOLINT(google-build-using-namespace): outputs of one library
namespace fs = std::filesystem;

namespace {

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

Json responsesOf(const PolicyResult& r) {
  Json out = Json::array();
  for (const EventResponse& e : r.events) {
    out.push_back({{"seconds", e.seconds}, {"scans", e.reached() ? Json(e.scans) : Json()}});
  }
  return out;
}

// A distance that may be NaN (nothing averaged) as JSON: null then.
Json metres(double v) { return std::isfinite(v) ? Json(v) : Json(); }

Json ndtJson(const PolicyResult& r) {
  const NdtWallDistance& d = r.ndt_walls;
  return {{"cell_centre_wall_distance_m", metres(d.cell_centre_m)},
          {"occupied_cells_near_walls", d.cells},
          {"ndt_cell_centre_wall_distance_m", metres(d.ndt_cell_centre_m)},
          {"ndt_mean_wall_distance_m", metres(d.ndt_mean_m)},
          {"gaussians_near_walls", d.gaussians},
          {"ndt_cells", r.ndt_cells},
          {"ndt_bytes", r.ndt_bytes}};
}

Json policyJson(const PolicyResult& r) {
  Json j = {{"label", r.label},
            {"policy", wavog::toString(r.params.policy.type)},
            {"init", wavog::toString(r.params.policy.init)},
            {"responses", responsesOf(r)},
            {"precision", r.precision},
            {"recall", r.recall},
            {"wall_distance_m", r.wall_distance},
            {"occupied_cells", r.occupied_cells},
            {"nodes", r.nodes},
            {"bytes", r.bytes},
            {"observed_cells", r.observed_cells},
            {"bytes_per_observed_cell", r.bytes_per_observed_cell},
            {"mean_scan_us", r.mean_scan_us},
            {"max_scan_us", r.max_scan_us},
            {"integration_s", r.total_s}};
  if (r.params.ndt) j["ndt"] = ndtJson(r);
  return j;
}

const char* typeName(const WorldEvent& e) {
  return e.type == WorldEvent::Type::kDeparture ? "departure" : "arrival";
}

Json eventJson(const WorldEvent& e) {
  return {{"name", e.name},
          {"type", typeName(e)},
          {"start_s", e.start_time},
          {"event_s", e.event_time},
          {"cells", e.cells.size()}};
}

// The NDT section of report.md: per policy, the walls' distances of cell centres and NDT means.
std::string ndtReport(const std::vector<PolicyResult>& results) {
  std::ostringstream md;
  md << "\n## NDT cells against the true walls\n\n"
     << "| policy / init | occupied cells near walls | their centres (cm) | cells with a Gaussian "
        "| their centres (cm) | their NDT means (cm) | NDT bytes |\n"
     << "|---|---|---|---|---|---|---|\n";
  for (const PolicyResult& r : results) {
    const NdtWallDistance& d = r.ndt_walls;
    md << "| " << r.label << " | " << d.cells << " | " << fixed(100 * d.cell_centre_m, 2) << " | "
       << d.gaussians << " | " << fixed(100 * d.ndt_cell_centre_m, 2) << " | "
       << fixed(100 * d.ndt_mean_m, 2) << " | " << r.ndt_bytes << " |\n";
  }
  md << "\nMean exact distance to the nearest wall edge (the simulator's polygons) of the "
     << "occupied cells' centres near walls (as *wall distance* picks them), and, of those cells "
     << "holding a Gaussian, of their centres and of their NDT means (paper section 1.2.3: the "
     << "mean of the end-points in a cell removes most of the grid's discretisation error).\n\n"
     << "![NDT means against cell centres](ndt_wall_distance.png)\n";
  return md.str();
}

void writeNdtCsv(const fs::path& data, const std::vector<PolicyResult>& results) {
  std::ofstream csv(data / "ndt_wall_distance.csv");
  csv << "policy,cell_centre_m,occupied_cells,ndt_cell_centre_m,ndt_mean_m,gaussians\n"
      << std::setprecision(6);
  for (const PolicyResult& r : results) {
    const NdtWallDistance& d = r.ndt_walls;
    csv << r.label << "," << d.cell_centre_m << "," << d.cells << "," << d.ndt_cell_centre_m << ","
        << d.ndt_mean_m << "," << d.gaussians << "\n";
  }
  if (!csv) throw std::runtime_error((data / "ndt_wall_distance.csv").string() + ": cannot write");
}

}  // namespace

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

std::string responseText(const EventResponse& r) {
  if (!r.reached()) return "never";
  return fixed(r.seconds, 2) + " s (" + std::to_string(r.scans) + " scans)";
}

std::string report(const World& world, const RunInfo& o, const std::vector<WorldEvent>& events,
                   const std::vector<PolicyResult>& results) {
  std::ostringstream md;
  const LaserParams& l = world.vehicle.lasers.front();
  md << "# Update policies on the simulated scenario '" << world.name << "'\n\n"
     << "Scenario: " << fixed(world.duration, 0) << " s, " << world.vehicle.lasers.size()
     << " lasers (" << l.beams << " beams over " << fixed(l.fov * 180 / M_PI, 0) << " deg, "
     << fixed(l.range_max, 0) << " m, " << fixed(l.rate_hz, 0) << " Hz each, range noise sigma "
     << fixed(l.noise_sigma, 3) << " m, dropouts " << fixed(100 * l.dropout_prob, 1) << " %), "
     << o.scans << " scans, seed " << o.seed << ". Map: resolution " << fixed(o.resolution, 2)
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
  if (o.ndt) md << ndtReport(results);
  return md.str();
}

Json summary(const World& world, const RunInfo& run, const std::vector<WorldEvent>& events,
             const std::vector<PolicyResult>& results, double wall_s,
             const std::string& offline_summary) {
  Json js;
  js["world"] = world.name;
  js["duration_s"] = world.duration;
  js["seed"] = run.seed;
  js["scans"] = run.scans;
  js["resolution"] = run.resolution;
  js["evaluation_wall_time_s"] = wall_s;
  js["ndt"] = run.ndt;
  js["events"] = Json::array();
  for (const WorldEvent& e : events) js["events"].push_back(eventJson(e));
  js["policies"] = Json::array();
  for (const PolicyResult& r : results) js["policies"].push_back(policyJson(r));
  if (!offline_summary.empty()) {
    std::ifstream in(offline_summary);
    if (!in) throw std::runtime_error(offline_summary + ": cannot read");
    std::stringstream text;
    text << in.rdbuf();
    js["offline_map"] = text.str().find_first_not_of(" \t\r\n") == std::string::npos
                            ? Json()
                            : Json::parse(text.str());
  }
  return js;
}

std::string figureName(const std::vector<WorldEvent>& events, std::size_t k) {
  std::string name = typeName(events[k]);
  for (std::size_t j = 0; j < k; ++j) {
    if (events[j].type == events[k].type) name += "_" + std::to_string(k);
  }
  return name;
}

void writeFigureData(const std::string& dir, const World& world,
                     const std::vector<WorldEvent>& events,
                     const std::vector<PolicyResult>& results, double t_end) {
  const fs::path data = fs::path(dir) / "figure_data";
  fs::create_directories(data / "maps");
  Json fig;
  fig["world"] = world.name;
  fig["t_end_s"] = t_end;
  fig["maps"] = Json::array();
  for (std::size_t i = 0; i < results.size(); ++i) {
    const wavog::Raster& m = results[i].final_map;
    const std::string png = "maps/policy_" + std::to_string(i) + ".png";
    wavog::writePng((data / png).string(), wavog::renderRgb(halve(m)));
    const double x0 = m.originX();
    const double y0 = m.originY();
    fig["maps"].push_back({{"label", results[i].label},
                           {"png", png},
                           {"extent_m",
                            {x0, x0 + static_cast<double>(m.box.width()) * m.cell_size, y0,
                             y0 + static_cast<double>(m.box.height()) * m.cell_size}}});
  }
  fig["events"] = Json::array();
  for (std::size_t k = 0; k < events.size(); ++k) {
    Json e = eventJson(events[k]);
    e["figure"] = figureName(events, k) + ".png";
    fig["events"].push_back(e);
  }
  wavog_tools::writeJson((data / "figures.json").string(), fig);
  std::ofstream csv(data / "responses.csv");
  // mean_reflection_p: empty without --reflection, "nan" while no cell of the car has a p.
  csv << "event,policy,time_s,mean_p_occ,mean_reflection_p\n" << std::setprecision(6);
  for (std::size_t k = 0; k < events.size(); ++k) {
    for (const PolicyResult& r : results) {
      const EventResponse& e = r.events[k];
      for (std::size_t j = 0; j < e.times.size(); ++j) {
        csv << k << "," << r.label << "," << e.times[j] << "," << e.mean_occupancy[j] << ",";
        if (j < e.mean_reflection.size()) csv << e.mean_reflection[j];
        csv << "\n";
      }
    }
  }
  if (!csv) throw std::runtime_error((data / "responses.csv").string() + ": cannot write");
  if (!results.empty() && results.front().params.ndt) writeNdtCsv(data, results);
}

}  // namespace wavog_evaluate
