// Pose error of the simulated vehicle: the pose the mapper is given differs from the true pose by
// per-scan Gaussian noise (x, y, yaw) and an optional slow linear drift, while the lasers still
// measure from the true pose. Deterministic for a seed: each scan's error draws from its own
// generator seeded by (seed, laser, scan number). Units: metres, radians, seconds. Thread-safe
// (pure functions over values).
#ifndef WAVOG_MAPPING_SIM_POSE_NOISE_H_
#define WAVOG_MAPPING_SIM_POSE_NOISE_H_

#include <cstdint>
#include <string>
#include <vector>

#include "wavog_mapping/core/types.h"
#include "wavog_mapping/sim/laser_sim.h"
#include "wavog_mapping/sim/world.h"

namespace wavog {
namespace sim {

/// Error model of the vehicle pose handed to the mapper (world frame).
struct PoseNoiseParams {
  /// Standard deviation of the per-scan Gaussian error on x and on y (m), >= 0.
  double sigma_xy_m = 0.0;
  /// Standard deviation of the per-scan Gaussian error on the heading (rad), >= 0.
  double sigma_yaw_rad = 0.0;
  /// Slow drift: position error growing linearly with time along x and y (m/s), any sign.
  double drift_x_m_per_s = 0.0;
  double drift_y_m_per_s = 0.0;
  /// Slow drift of the heading error (rad/s), any sign.
  double drift_yaw_rad_per_s = 0.0;
  /// Seed of the pose-error draws (independent of the range-noise seed).
  std::uint64_t seed = 1;

  /// True if any error is configured (false: the mapper gets the true poses, bit for bit).
  bool enabled() const;
  /// Every violated rule, one line each (empty: valid).
  std::vector<std::string> validate() const;
};

/// The error (dx, dy, dtheta) added to the true vehicle pose for scan `seq` of laser `laser`
/// taken at `stamp` (s). Zero when !params.enabled().
Pose2 poseError(const PoseNoiseParams& params, int laser, std::uint64_t seq, double stamp);

/// `scan` as the mapper sees it: vehicle_pose = true pose + poseError (heading wrapped),
/// sensor_pose = that pose composed with the laser's mount. Ranges and ground truth unchanged.
SimScan withPoseError(const World& world, const SimScan& scan, const PoseNoiseParams& params);
/// The same for every scan (a copy; the input is returned unchanged when !params.enabled()).
std::vector<SimScan> withPoseError(const World& world, const std::vector<SimScan>& scans,
                                   const PoseNoiseParams& params);

}  // namespace sim
}  // namespace wavog

#endif  // WAVOG_MAPPING_SIM_POSE_NOISE_H_
