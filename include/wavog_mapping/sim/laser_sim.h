// Simulated planar lasers: exact ray-polygon ranges against the world at the scan's time, plus
// Gaussian range noise, NaN dropouts and +inf for no return (REP 117). Deterministic for a seed:
// each scan draws from its own generator seeded by (seed, laser, scan number), so a scan does not
// depend on which other scans were simulated. Thread-safety: const methods are thread-safe.
#ifndef WAVOG_MAPPING_SIM_LASER_SIM_H_
#define WAVOG_MAPPING_SIM_LASER_SIM_H_

#include <cstdint>
#include <vector>

#include "wavog_mapping/core/types.h"
#include "wavog_mapping/sim/geometry.h"
#include "wavog_mapping/sim/world.h"

namespace wavog {
namespace sim {

/// Exact distances along a fan of rays to the nearest polygon edge. Cost per fan: one pass over
/// the edges (each edge tests only the beams inside its angular span) instead of beams x edges.
class RayCaster {
 public:
  explicit RayCaster(std::vector<Polygon> polygons);

  /// For beam i at bearing sensor.theta + angle_min + i * angle_increment (angle_increment > 0),
  /// the distance from (sensor.x, sensor.y) to the first edge hit, or +inf if none within
  /// max_range, and in `hit` (if given) the index of the polygon hit, or -1.
  void castFan(const Pose2& sensor, double angle_min, double angle_increment, int beams,
               double max_range, std::vector<double>* ranges, std::vector<int>* hit) const;
  /// One ray; same conventions.
  double cast(const Pose2& sensor, double bearing, double max_range, int* hit = nullptr) const;

 private:
  std::vector<Polygon> polygons_;
};

/// Small deterministic generator (xoroshiro128+ seeded by splitmix64) with hand-written uniform
/// and Box-Muller Gaussian draws, so results are the same with any standard library.
class SimRandom {
 public:
  explicit SimRandom(std::uint64_t seed);
  /// Uniform in [0, 1).
  double uniform();
  /// Standard normal.
  double gaussian();

 private:
  std::uint64_t state_[2];  // xoroshiro128+ state
  bool has_spare_ = false;
  double spare_ = 0.0;
  std::uint64_t nextBits();
};

/// One simulated scan of one laser, with its ground truth.
struct SimScan {
  double stamp = 0.0;               ///< time since the start of the scenario (s)
  int laser = 0;                    ///< index in World::vehicle.lasers
  std::uint64_t seq = 0;            ///< scan number of that laser, from 0
  Pose2 vehicle_pose;               ///< base_link in the world frame
  Pose2 sensor_pose;                ///< the laser in the world frame
  std::vector<float> ranges;        ///< measured: noisy, NaN dropouts, +inf no return (m)
  std::vector<double> true_ranges;  ///< exact distance to the first surface, +inf if none (m)
  std::vector<int> hit_object;      ///< per beam: index in World::objects hit, -1 if none
  /// A view for WaveletMap::integrate, valid while this scan lives and is unchanged.
  ScanView view(const LaserParams& params) const;
};

/// Produces every scan of a world in time order (ties: lower laser index first).
class ScanSimulator {
 public:
  /// Throws std::invalid_argument listing World::validate() errors.
  ScanSimulator(const World& world, std::uint64_t seed);

  const World& world() const { return world_; }
  /// Number of scans of the whole scenario, all lasers.
  std::size_t scanCount() const;
  /// Next scan in time order; false when the scenario is over.
  bool next(SimScan* scan);
  /// Scan `seq` of laser `laser`, independent of next()'s position.
  SimScan simulate(int laser, std::uint64_t seq) const;
  /// Time of scan `seq` of laser `laser` (s).
  double stampOf(int laser, std::uint64_t seq) const;

 private:
  World world_;
  std::uint64_t seed_;
  std::vector<std::uint64_t> next_seq_;
};

/// Every scan of a world, in time order (convenience for evaluation and tests).
std::vector<SimScan> simulateAll(const World& world, std::uint64_t seed);

}  // namespace sim
}  // namespace wavog

#endif  // WAVOG_MAPPING_SIM_LASER_SIM_H_
