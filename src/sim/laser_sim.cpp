#include "wavog_mapping/sim/laser_sim.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace wavog {
namespace sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::uint64_t splitMix64(std::uint64_t* x) {
  std::uint64_t z = (*x += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

}  // namespace

RayCaster::RayCaster(std::vector<Polygon> polygons) : polygons_(std::move(polygons)) {}

void RayCaster::castFan(const Pose2& sensor, double angle_min, double angle_increment, int beams,
                        double max_range, std::vector<double>* ranges,
                        std::vector<int>* hit) const {
  ranges->assign(static_cast<std::size_t>(beams), kInf);
  if (hit) hit->assign(static_cast<std::size_t>(beams), -1);
  const double c = std::cos(sensor.theta);
  const double s = std::sin(sensor.theta);
  // Beam directions in the sensor frame, computed once per fan.
  std::vector<Vec2, Eigen::aligned_allocator<Vec2>> dirs(static_cast<std::size_t>(beams));
  for (int i = 0; i < beams; ++i) {
    const double a = angle_min + i * angle_increment;
    dirs[static_cast<std::size_t>(i)] = Vec2(std::cos(a), std::sin(a));
  }
  const Vec2 origin = Vec2::Zero();
  const double span = angle_increment * (beams - 1);
  for (std::size_t pi = 0; pi < polygons_.size(); ++pi) {
    const Polygon& poly = polygons_[pi];
    for (std::size_t k = 0, j = poly.size() - 1; k < poly.size(); j = k++) {
      // Edge endpoints in the sensor frame.
      const Vec2 dw0 = poly[j] - Vec2(sensor.x, sensor.y);
      const Vec2 dw1 = poly[k] - Vec2(sensor.x, sensor.y);
      const Vec2 a(c * dw0.x() + s * dw0.y(), -s * dw0.x() + c * dw0.y());
      const Vec2 b(c * dw1.x() + s * dw1.y(), -s * dw1.x() + c * dw1.y());
      if (pointSegmentDistance(origin, a, b) >= max_range) continue;
      // Angular span of the edge seen from the sensor (< pi unless the edge passes through the
      // sensor), relative to the first beam; beams inside it, padded by one for round-off.
      const double aa = std::atan2(a.y(), a.x());
      const double ab = std::atan2(b.y(), b.x());
      const double d = wrapAngle(ab - aa);
      // Its start relative to the first beam, in (0, 2 pi] (the loop also tries one turn less).
      const double lo = wrapAngle((d >= 0.0 ? aa : ab) - angle_min - M_PI) + M_PI;
      const double width = std::abs(d);
      for (double shift : {0.0, -2.0 * M_PI}) {
        const double rel_lo = lo + shift;
        const double rel_hi = rel_lo + width;
        if (rel_hi < -angle_increment || rel_lo > span + angle_increment) continue;
        const int i0 = std::max(0, static_cast<int>(std::floor(rel_lo / angle_increment)) - 1);
        const int i1 =
            std::min(beams - 1, static_cast<int>(std::ceil(rel_hi / angle_increment)) + 1);
        for (int i = i0; i <= i1; ++i) {
          const auto ui = static_cast<std::size_t>(i);
          const double t = raySegmentDistance(origin, dirs[ui], a, b);
          if (t < (*ranges)[ui] && t < max_range) {
            (*ranges)[ui] = t;
            if (hit) (*hit)[ui] = static_cast<int>(pi);
          }
        }
      }
    }
  }
}

double RayCaster::cast(const Pose2& sensor, double bearing, double max_range, int* hit) const {
  std::vector<double> r;
  std::vector<int> h;
  castFan(Pose2{sensor.x, sensor.y, sensor.theta + bearing}, 0.0, 1.0, 1, max_range, &r, &h);
  if (hit) *hit = h[0];
  return r[0];
}

SimRandom::SimRandom(std::uint64_t seed) {
  std::uint64_t x = seed;
  state_[0] = splitMix64(&x);
  state_[1] = splitMix64(&x);
}

std::uint64_t SimRandom::nextBits() {
  const std::uint64_t s0 = state_[0];
  std::uint64_t s1 = state_[1];
  const std::uint64_t result = s0 + s1;
  s1 ^= s0;
  state_[0] = ((s0 << 24) | (s0 >> 40)) ^ s1 ^ (s1 << 16);
  state_[1] = (s1 << 37) | (s1 >> 27);
  return result;
}

double SimRandom::uniform() { return static_cast<double>(nextBits() >> 11) * 0x1.0p-53; }

double SimRandom::gaussian() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  // Box-Muller; 1 - u keeps the logarithm finite.
  const double u1 = 1.0 - uniform();
  const double u2 = uniform();
  const double r = std::sqrt(-2.0 * std::log(u1));
  spare_ = r * std::sin(2.0 * M_PI * u2);
  has_spare_ = true;
  return r * std::cos(2.0 * M_PI * u2);
}

ScanView SimScan::view(const LaserParams& params) const {
  ScanView v;
  v.ranges = ranges.data();
  v.count = ranges.size();
  v.angle_min = params.angleMin();
  v.angle_increment = params.angleIncrement();
  v.range_min = params.range_min;
  v.range_max = params.range_max;
  return v;
}

ScanSimulator::ScanSimulator(const World& world, std::uint64_t seed)
    : world_(world), seed_(seed), next_seq_(world.vehicle.lasers.size(), 0) {
  const std::vector<std::string> errors = world_.validate();
  if (!errors.empty()) {
    std::ostringstream msg;
    msg << "invalid world '" << world_.name << "':";
    for (const std::string& e : errors) msg << "\n  " << e;
    throw std::invalid_argument(msg.str());
  }
}

double ScanSimulator::stampOf(int laser, std::uint64_t seq) const {
  const LaserParams& l = world_.vehicle.lasers[static_cast<std::size_t>(laser)];
  return l.phase_s + static_cast<double>(seq) / l.rate_hz;
}

std::size_t ScanSimulator::scanCount() const {
  std::size_t n = 0;
  for (std::size_t i = 0; i < world_.vehicle.lasers.size(); ++i) {
    const LaserParams& l = world_.vehicle.lasers[i];
    if (l.phase_s < world_.duration) {
      // Scans at phase + k / rate < duration.
      n += static_cast<std::size_t>(std::ceil((world_.duration - l.phase_s) * l.rate_hz - 1e-9));
    }
  }
  return n;
}

bool ScanSimulator::next(SimScan* scan) {
  int best = -1;
  double best_t = kInf;
  for (std::size_t i = 0; i < next_seq_.size(); ++i) {
    const double t = stampOf(static_cast<int>(i), next_seq_[i]);
    if (t < best_t) {
      best_t = t;
      best = static_cast<int>(i);
    }
  }
  if (best < 0 || !(best_t < world_.duration)) return false;
  *scan = simulate(best, next_seq_[static_cast<std::size_t>(best)]++);
  return true;
}

SimScan ScanSimulator::simulate(int laser, std::uint64_t seq) const {
  const LaserParams& l = world_.vehicle.lasers[static_cast<std::size_t>(laser)];
  SimScan scan;
  scan.laser = laser;
  scan.seq = seq;
  scan.stamp = stampOf(laser, seq);
  scan.vehicle_pose = world_.vehicle.path.at(scan.stamp);
  scan.sensor_pose = compose(scan.vehicle_pose, l.mount);

  std::vector<int> owners;
  RayCaster caster(world_.polygonsAt(scan.stamp, &owners));
  caster.castFan(scan.sensor_pose, l.angleMin(), l.angleIncrement(), l.beams, l.range_max,
                 &scan.true_ranges, &scan.hit_object);
  for (int& h : scan.hit_object) {
    if (h >= 0) h = owners[static_cast<std::size_t>(h)];
  }

  // Every beam draws its dropout and its noise whatever the outcome, so the stream of draws is
  // the same for any world and the noise of one beam does not depend on the others' ranges.
  std::uint64_t key = seed_;
  splitMix64(&key);
  key ^= (static_cast<std::uint64_t>(laser) << 48) ^ seq;
  SimRandom rng(splitMix64(&key));
  scan.ranges.resize(scan.true_ranges.size());
  for (std::size_t i = 0; i < scan.true_ranges.size(); ++i) {
    const double drop = rng.uniform();
    const double noise = rng.gaussian() * l.noise_sigma;
    const double truth = scan.true_ranges[i];
    if (drop < l.dropout_prob) {
      scan.ranges[i] = std::numeric_limits<float>::quiet_NaN();
    } else if (!std::isfinite(truth)) {
      scan.ranges[i] = std::numeric_limits<float>::infinity();
    } else {
      const double measured = std::max(truth + noise, l.range_min);
      scan.ranges[i] = measured >= l.range_max ? std::numeric_limits<float>::infinity()
                                               : static_cast<float>(measured);
    }
  }
  return scan;
}

std::vector<SimScan> simulateAll(const World& world, std::uint64_t seed) {
  ScanSimulator sim(world, seed);
  std::vector<SimScan> scans;
  scans.reserve(sim.scanCount());
  SimScan scan;
  while (sim.next(&scan)) scans.push_back(std::move(scan));
  return scans;
}

}  // namespace sim
}  // namespace wavog
