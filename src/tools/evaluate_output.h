// What wavog_evaluate writes besides the maps: report.md (the policy table in Markdown),
// summary.json (the same figures for scripts) and figure_data/ (each policy's final map and the
// cars' occupancy against time), from which scripts/plot_evaluation.py draws policies.png,
// departure.png and arrival.png. Private to wavog_evaluate. Free functions: thread-safe.
#ifndef WAVOG_MAPPING_TOOLS_EVALUATE_OUTPUT_H_
#define WAVOG_MAPPING_TOOLS_EVALUATE_OUTPUT_H_

#include <cstdint>
#include <string>
#include <vector>

#include "tool_support.h"
#include "wavog_mapping/sim/evaluation.h"
#include "wavog_mapping/sim/world.h"

namespace wavog_evaluate {

/// What the run was asked for, as far as the outputs tell it.
struct RunInfo {
  std::uint64_t seed = 1;
  double resolution = 0.1;
  double fraction = 0.9;
  int jobs = 2;
  std::size_t scans = 0;
  bool ndt = false;  ///< --ndt: the runs kept NDT cells
};

/// `v` with `digits` decimals.
std::string fixed(double v, int digits);
/// "0.20 s (33 scans)" or "never".
std::string responseText(const wavog::sim::EventResponse& r);

/// report.md: scenario, events, the table of every policy, definitions, links to the figures.
std::string report(const wavog::sim::World& world, const RunInfo& run,
                   const std::vector<wavog::sim::WorldEvent>& events,
                   const std::vector<wavog::sim::PolicyResult>& results);

/// summary.json's content; `offline_summary` (a JSON file, may be empty) is embedded as
/// "offline_map".
nlohmann::ordered_json summary(const wavog::sim::World& world, const RunInfo& run,
                               const std::vector<wavog::sim::WorldEvent>& events,
                               const std::vector<wavog::sim::PolicyResult>& results, double wall_s,
                               const std::string& offline_summary);

/// The figure file name of event k: "departure" / "arrival" for the first of each kind, then
/// "departure_<k>" ...
std::string figureName(const std::vector<wavog::sim::WorldEvent>& events, std::size_t k);

/// Writes `dir`/figure_data/: figures.json (titles, events, each map's PNG and extent in m),
/// maps/policy_<i>.png (final maps, halved with the largest value so thin walls stay visible),
/// responses.csv (event, policy, time_s, mean_p_occ, mean_reflection_p) and, when the runs kept
/// NDT cells, ndt_wall_distance.csv (policy, the distances of ndtWallDistance in m, the counts).
void writeFigureData(const std::string& dir, const wavog::sim::World& world,
                     const std::vector<wavog::sim::WorldEvent>& events,
                     const std::vector<wavog::sim::PolicyResult>& results, double t_end);

}  // namespace wavog_evaluate

#endif  // WAVOG_MAPPING_TOOLS_EVALUATE_OUTPUT_H_
