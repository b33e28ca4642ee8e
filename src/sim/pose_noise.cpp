#include "wavog_mapping/sim/pose_noise.h"

#include <cmath>

#include "wavog_mapping/sim/geometry.h"

namespace wavog {
namespace sim {
namespace {

// Salt that separates the pose-error stream from the range-noise stream of the same seed.
constexpr std::uint64_t kPoseSalt = 0x9e3779b97f4a7c15ULL;

}  // namespace

bool PoseNoiseParams::enabled() const {
  return sigma_xy_m != 0.0 || sigma_yaw_rad != 0.0 || drift_x_m_per_s != 0.0 ||
         drift_y_m_per_s != 0.0 || drift_yaw_rad_per_s != 0.0;
}

std::vector<std::string> PoseNoiseParams::validate() const {
  std::vector<std::string> errors;
  if (!(sigma_xy_m >= 0.0 && std::isfinite(sigma_xy_m))) {
    errors.push_back("pose sigma_xy_m (" + std::to_string(sigma_xy_m) + ") must be >= 0");
  }
  if (!(sigma_yaw_rad >= 0.0 && std::isfinite(sigma_yaw_rad))) {
    errors.push_back("pose sigma_yaw_rad (" + std::to_string(sigma_yaw_rad) + ") must be >= 0");
  }
  if (!std::isfinite(drift_x_m_per_s) || !std::isfinite(drift_y_m_per_s) ||
      !std::isfinite(drift_yaw_rad_per_s)) {
    errors.push_back("pose drift rates must be finite");
  }
  return errors;
}

Pose2 poseError(const PoseNoiseParams& params, int laser, std::uint64_t seq, double stamp) {
  Pose2 e;
  if (!params.enabled()) return e;
  SimRandom rng((params.seed * kPoseSalt) ^ (static_cast<std::uint64_t>(laser) << 48) ^ seq ^
                kPoseSalt);
  // Always three draws, so the stream does not depend on which sigmas are zero.
  const double nx = rng.gaussian();
  const double ny = rng.gaussian();
  const double nt = rng.gaussian();
  e.x = params.sigma_xy_m * nx + params.drift_x_m_per_s * stamp;
  e.y = params.sigma_xy_m * ny + params.drift_y_m_per_s * stamp;
  e.theta = params.sigma_yaw_rad * nt + params.drift_yaw_rad_per_s * stamp;
  return e;
}

SimScan withPoseError(const World& world, const SimScan& scan, const PoseNoiseParams& params) {
  SimScan out = scan;
  if (!params.enabled()) return out;
  const Pose2 e = poseError(params, scan.laser, scan.seq, scan.stamp);
  out.vehicle_pose.x += e.x;
  out.vehicle_pose.y += e.y;
  out.vehicle_pose.theta = wrapAngle(out.vehicle_pose.theta + e.theta);
  const LaserParams& l = world.vehicle.lasers[static_cast<std::size_t>(scan.laser)];
  out.sensor_pose = compose(out.vehicle_pose, l.mount);
  return out;
}

std::vector<SimScan> withPoseError(const World& world, const std::vector<SimScan>& scans,
                                   const PoseNoiseParams& params) {
  if (!params.enabled()) return scans;
  std::vector<SimScan> out;
  out.reserve(scans.size());
  for (const SimScan& s : scans) out.push_back(withPoseError(world, s, params));
  return out;
}

}  // namespace sim
}  // namespace wavog
