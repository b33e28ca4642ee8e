#include "wavog_mapping/sim/noise_study.h"

#include <atomic>
#include <cmath>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace wavog {
namespace sim {
namespace {

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

double parseNonNegative(const std::string& text, const std::string& item) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !(v >= 0.0) || !std::isfinite(v)) {
    throw std::invalid_argument("pose-noise level '" + item +
                                "': expected SIGMA_XY_CM:SIGMA_YAW_DEG, both >= 0");
  }
  return v;
}

}  // namespace

std::vector<NoiseLevel> parseNoiseLevels(const std::string& text, std::uint64_t seed) {
  std::vector<NoiseLevel> levels;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const std::size_t colon = item.find(':');
    if (colon == std::string::npos) {
      throw std::invalid_argument("pose-noise level '" + item +
                                  "': expected SIGMA_XY_CM:SIGMA_YAW_DEG, both >= 0");
    }
    const double cm = parseNonNegative(item.substr(0, colon), item);
    const double deg = parseNonNegative(item.substr(colon + 1), item);
    NoiseLevel l;
    l.noise.sigma_xy_m = cm / 100.0;
    l.noise.sigma_yaw_rad = deg * M_PI / 180.0;
    l.noise.seed = seed;
    l.label = l.noise.enabled()
                  ? fixed(cm, cm == std::round(cm) ? 0 : 1) + " cm / " + fixed(deg, 2) + " deg"
                  : "0 (exact poses)";
    levels.push_back(l);
  }
  if (levels.empty()) throw std::invalid_argument("no pose-noise level given");
  return levels;
}

WallFigures wallFigures(const World& world, const PolicyResult& result, double t,
                        const WallProfileOptions& options) {
  WallFigures f;
  f.wall_distance_m = result.wall_distance;
  f.surface_distance_m = meanDistanceToWallSurface(world, t, result.final_map);
  f.width = wallWidthAtHalfMax(result.final_map, wallSamplesFromWorld(world, t, options), options);
  return f;
}

std::vector<NoiseStudyRow> runNoiseStudy(const World& world, const std::vector<SimScan>& scans,
                                         const std::vector<WorldEvent>& events,
                                         const std::vector<PolicyRun>& runs,
                                         const std::vector<NoiseLevel>& levels,
                                         const EvaluationOptions& options, int jobs,
                                         const std::vector<PolicyResult>* exact) {
  if (exact && exact->size() != runs.size()) {
    throw std::invalid_argument("runNoiseStudy: one exact-pose result per run expected");
  }
  std::vector<NoiseStudyRow> rows(levels.size() * runs.size());
  const double t_end = scans.empty() ? 0.0 : scans.back().stamp;
  for (std::size_t l = 0; l < levels.size(); ++l) {
    const bool reuse = exact && !levels[l].noise.enabled();
    // One copy of the scans per level, shared read-only by the level's runs.
    const std::vector<SimScan> noisy =
        reuse ? std::vector<SimScan>() : withPoseError(world, scans, levels[l].noise);
    std::atomic<std::size_t> next{0};
    auto worker = [&]() {
      for (std::size_t r = next++; r < runs.size(); r = next++) {
        NoiseStudyRow& row = rows[l * runs.size() + r];
        row.level = levels[l].label;
        row.noise = levels[l].noise;
        row.result = reuse ? (*exact)[r] : evaluatePolicy(world, noisy, events, runs[r], options);
        row.walls = wallFigures(world, row.result, t_end);
        row.result.final_map = Raster();
      }
    };
    std::vector<std::thread> threads;
    for (int j = 1; j < std::min<int>(jobs, static_cast<int>(runs.size())); ++j) {
      threads.emplace_back(worker);
    }
    worker();
    for (std::thread& t : threads) t.join();
  }
  return rows;
}

std::string noiseStudyMarkdown(const std::vector<NoiseStudyRow>& rows) {
  std::ostringstream md;
  md << "## Thick walls under pose error\n\n"
     << "The same scans, but the mapper is given the vehicle pose with per-scan Gaussian error "
     << "(sigma on x and y, and on the heading; the lasers still measure from the true pose). "
     << "The first level is the table above, unchanged.\n\n"
     << "| pose noise (sigma xy / yaw) | policy / init | occupied precision | recall | "
        "wall distance (cm) | distance to wall surface (cm) | wall width at half max (cells, "
        "mean / median) | profiles | nodes | bytes / observed cell |\n"
        "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const NoiseStudyRow& row : rows) {
    const PolicyResult& r = row.result;
    md << "| " << row.level << " | " << r.label << " | " << fixed(r.precision, 3) << " | "
       << fixed(r.recall, 3) << " | " << fixed(100 * row.walls.wall_distance_m, 1) << " | "
       << fixed(100 * row.walls.surface_distance_m, 1) << " | "
       << fixed(row.walls.width.mean_cells, 2) << " / " << fixed(row.walls.width.median_cells, 1)
       << " | " << row.walls.width.measured << " of " << row.walls.width.samples << " | " << r.nodes
       << " | " << fixed(r.bytes_per_observed_cell, 2) << " |\n";
  }
  md << "\n- *wall width at half max*: across the free faces of the true walls, every 0.5 m "
     << "(faces of at least 1.5 m, 0.5 m from their ends), the profile of P(occ) from 0.5 m "
     << "behind the face to 1 m in front of it; the peak is the highest observed value within "
     << "0.25 m of the face (must be > 0.5), the base the lowest observed value in front; the "
     << "width is the run of observed cells at or above the half height around the peak, in "
     << "cells. *profiles*: measured of asked for (a face never seen occupied is not measured). "
     << "One cell is ideal.\n"
     << "- *wall distance*: as above (mean distance of occupied cells nearest to a wall, within "
     << "1 m, to the wall's cells; 0 for a cell inside the wall, so hits pushed into a wall "
     << "lower it). *distance to wall surface*: the same cells, distance to the nearest cell the "
     << "wall's surface passes through (cells inside count too; 0 is ideal).\n"
     << "- The pose error is drawn per scan (x, y and heading, independent Gaussians) and added "
     << "to the true vehicle pose before the laser's mount; the ranges are those measured from "
     << "the true pose (`include/wavog_mapping/sim/pose_noise.h`).\n";
  return md.str();
}

std::string noiseStudyJson(const std::vector<NoiseStudyRow>& rows) {
  nlohmann::json out = nlohmann::json::array();
  for (const NoiseStudyRow& row : rows) {
    const PolicyResult& r = row.result;
    out.push_back({{"level", row.level},
                   {"sigma_xy_m", row.noise.sigma_xy_m},
                   {"sigma_yaw_rad", row.noise.sigma_yaw_rad},
                   {"label", r.label},
                   {"policy", toString(r.params.policy.type)},
                   {"init", toString(r.params.policy.init)},
                   {"precision", r.precision},
                   {"recall", r.recall},
                   {"wall_distance_m", row.walls.wall_distance_m},
                   {"wall_surface_distance_m", row.walls.surface_distance_m},
                   {"wall_width_mean_cells", row.walls.width.mean_cells},
                   {"wall_width_median_cells", row.walls.width.median_cells},
                   {"wall_profiles_measured", row.walls.width.measured},
                   {"wall_profiles", row.walls.width.samples},
                   {"occupied_cells", r.occupied_cells},
                   {"nodes", r.nodes},
                   {"bytes_per_observed_cell", r.bytes_per_observed_cell}});
  }
  return out.dump(2) + "\n";
}

}  // namespace sim
}  // namespace wavog
