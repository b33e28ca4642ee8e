// Policy evaluation against the simulator's ground truth: runs a scenario's scans through the
// core map (wavog::WaveletMap) under each update policy and measures responsiveness (how long a
// departed car's cells stay occupied, how long an arrived car takes to appear), precision (occupied
// cells against the true surfaces, thickness of walls, and with MapParams::ndt the NDT means
// against the true walls), compactness (nodes, bytes per observed cell) and integration time.
// ROS-free. Not thread-safe (one evaluation per thread).
#ifndef WAVOG_MAPPING_SIM_EVALUATION_H_
#define WAVOG_MAPPING_SIM_EVALUATION_H_

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "wavog_mapping/core/params.h"
#include "wavog_mapping/core/types.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/sim/ground_truth.h"
#include "wavog_mapping/sim/laser_sim.h"
#include "wavog_mapping/sim/wall_metrics.h"
#include "wavog_mapping/sim/world.h"

namespace wavog {
namespace sim {

/// One map configuration to evaluate.
struct PolicyRun {
  std::string label;  ///< e.g. "forget / unknown"
  MapParams params;
};

/// The paper's policies at `resolution` (m), with their documented defaults: none, max, clamp,
/// forget (gamma 0.3), clamp_lower; max, clamp, forget and clamp_lower also with empty-bound
/// initialisation (for none it only shifts every cell by odd_emp).
std::vector<PolicyRun> standardPolicies(double resolution);

/// A change of the world whose cells the map must follow.
struct WorldEvent {
  enum class Type { kDeparture, kArrival };
  Type type = Type::kDeparture;
  int object = -1;          ///< index in World::objects
  std::string name;         ///< the object's name
  double start_time = 0.0;  ///< departure: when it starts moving; arrival: when it appears (s)
  double event_time = 0.0;  ///< departure: when its parking footprint is clear; arrival: parked
  /// The cells that saw it (>= 2 true beam hits while it was parked) and that the lasers observe
  /// again after the event: free (departure) or hit (arrival).
  std::vector<CellIndex> cells;
  /// Per cell, the index (in the scans) of the first scan after the event that observes it.
  std::vector<std::size_t> first_view;
};

/// The departures and arrivals of a world (objects with role departing / arriving), with the
/// cells each was seen in, from the scans' ground truth.
std::vector<WorldEvent> findEvents(const World& world, const std::vector<SimScan>& scans,
                                   double resolution);

/// What a policy did with one event.
struct EventResponse {
  /// Delay of the event's cells from their first view after the event to their switch (departure:
  /// P(occ) < 0.5, arrival: P(occ) > 0.5), in seconds and in scans of all lasers (the viewing scan
  /// counts as 1): the `fraction` quantile over the cells. +inf and SIZE_MAX if that many cells
  /// never switch within the scenario.
  double seconds = std::numeric_limits<double>::infinity();
  std::size_t scans = std::numeric_limits<std::size_t>::max();
  /// Mean P(occ) over the event's cells, sampled every `sample_period` seconds.
  std::vector<double> times;
  std::vector<double> mean_occupancy;
  /// With MapParams::reflection: mean reflection probability over the event's cells that have
  /// one, at the same times (NaN while none has); else empty.
  std::vector<double> mean_reflection;
  bool reached() const { return scans != std::numeric_limits<std::size_t>::max(); }
};

/// Map-quality figures of one policy at the end of the scenario.
struct PolicyResult {
  std::string label;
  MapParams params;
  std::vector<EventResponse> events;  ///< same order as the events
  double precision = 0.0;      ///< occupied cells within one cell of a true surface / occupied
  double recall = 0.0;         ///< observed true-surface cells within one cell of an occupied one
  double wall_distance = 0.0;  ///< mean distance (m) of occupied cells near walls to the walls
  std::size_t occupied_cells = 0;
  std::size_t nodes = 0;
  std::size_t bytes = 0;
  std::uint64_t observed_cells = 0;
  double bytes_per_observed_cell = 0.0;
  double mean_scan_us = 0.0;  ///< integration time per scan (microseconds)
  double max_scan_us = 0.0;
  double total_s = 0.0;  ///< integration time of the whole scenario (s)
  Raster final_map;      ///< the region of interest at scale 0, at the end
  /// With MapParams::ndt: occupied cell centres and NDT means against the true walls at the end,
  /// at scale 0 over the region of interest (within wall_margin of a wall); else all NaN / 0.
  NdtWallDistance ndt_walls;
  std::size_t ndt_cells = 0;  ///< with MapParams::ndt: finest cells holding a Gaussian
  std::size_t ndt_bytes = 0;  ///< with MapParams::ndt: of `bytes`, the Gaussians' share
};

/// Options of an evaluation.
struct EvaluationOptions {
  double fraction = 0.9;       ///< quantile of the cells' delays reported per event
  double sample_period = 0.1;  ///< period of the occupancy curves (s)
  double wall_margin = 1.0;    ///< occupied cells count for wall_distance within this of a wall
};

/// Runs `scans` (from `world`) through a fresh map with `run.params` and measures it.
PolicyResult evaluatePolicy(const World& world, const std::vector<SimScan>& scans,
                            const std::vector<WorldEvent>& events, const PolicyRun& run,
                            const EvaluationOptions& options = EvaluationOptions());

/// Predicted number of consecutive empty observations after which a cell at log-odds `x0` is
/// below log-odds 0 (P < 0.5) under exponential forgetting, from the closed form of [FSR07]
/// eq. 1.7: x_n = (1-g)^n (x0 - odd_emp) + odd_emp. 0 if x0 < 0 already.
int forgettingScansToFree(double x0, double gamma, double odd_emp);
/// The same for additive updates (none, clamp, clamp_lower; a lower bound below 0 does not
/// change it): the smallest n with x0 + n * odd_emp < 0.
int additiveScansToFree(double x0, double odd_emp);

}  // namespace sim
}  // namespace wavog

#endif  // WAVOG_MAPPING_SIM_EVALUATION_H_
