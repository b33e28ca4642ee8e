// Thick walls under pose error: the same scenario mapped by several policies at several pose-noise
// levels (the lasers always measure from the true pose, the mapper gets the noisy one), with the
// wall figures of each map: mean distance of occupied cells to the true walls and the width at
// half maximum across the walls. ROS-free; runs its maps on `jobs` threads.
#ifndef WAVOG_MAPPING_SIM_NOISE_STUDY_H_
#define WAVOG_MAPPING_SIM_NOISE_STUDY_H_

#include <string>
#include <vector>

#include "wavog_mapping/sim/evaluation.h"
#include "wavog_mapping/sim/pose_noise.h"
#include "wavog_mapping/sim/wall_metrics.h"

namespace wavog {
namespace sim {

/// One pose-noise level.
struct NoiseLevel {
  std::string label;  ///< e.g. "2 cm / 0.2 deg"
  PoseNoiseParams noise;
};

/// Parses "0:0,2:0.2,5:0.5": comma-separated sigma_xy (cm) : sigma_yaw (deg) pairs, all >= 0.
/// Throws std::invalid_argument naming the bad item.
std::vector<NoiseLevel> parseNoiseLevels(const std::string& text, std::uint64_t seed);

/// The wall figures of one final map against the world's walls at time t.
struct WallFigures {
  double wall_distance_m = 0.0;     ///< PolicyResult::wall_distance (0 inside a wall)
  double surface_distance_m = 0.0;  ///< meanDistanceToWallSurface (inside and outside alike)
  WallWidth width;                  ///< across the walls' free faces (wallSamplesFromWorld)
};
WallFigures wallFigures(const World& world, const PolicyResult& result, double t,
                        const WallProfileOptions& options = WallProfileOptions());

/// One map of the study.
struct NoiseStudyRow {
  std::string level;
  PoseNoiseParams noise;
  PolicyResult result;  ///< the usual figures (final_map dropped to save memory)
  WallFigures walls;
};

/// Every run at every level: the scans with withPoseError(level) through evaluatePolicy. Rows in
/// level-major order. `events` come from the true scans. `exact` (if given: one result per run,
/// same order, from the true scans with the same options, final_map kept) is used as is for the
/// levels without error instead of mapping them again.
std::vector<NoiseStudyRow> runNoiseStudy(const World& world, const std::vector<SimScan>& scans,
                                         const std::vector<WorldEvent>& events,
                                         const std::vector<PolicyRun>& runs,
                                         const std::vector<NoiseLevel>& levels,
                                         const EvaluationOptions& options, int jobs,
                                         const std::vector<PolicyResult>* exact = nullptr);

/// The study as a Markdown section (table and definitions) and as JSON.
std::string noiseStudyMarkdown(const std::vector<NoiseStudyRow>& rows);
std::string noiseStudyJson(const std::vector<NoiseStudyRow>& rows);

}  // namespace sim
}  // namespace wavog

#endif  // WAVOG_MAPPING_SIM_NOISE_STUDY_H_
