#include "compare/workloads.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <stdexcept>

#include "wavog_mapping/io/carmen_reader.h"

namespace wavog_compare {
namespace {

/// Radius of the synthetic arena's boundary at bearing phi (m), in [61.5, 78.5].
double arenaRadius(double phi) {
  return 70.0 + 5.0 * std::sin(3.0 * phi + 0.4) + 2.5 * std::sin(7.0 * phi + 1.3) +
         1.0 * std::sin(17.0 * phi + 2.0);
}

/// Distance from p along direction (ux, uy) to the arena boundary; p within 5 m of the centre.
double castToArena(double px, double py, double ux, double uy) {
  double lo = 40.0;   // inside: |p + lo u| <= 45 < 61.5
  double hi = 100.0;  // outside: |p + hi u| >= 95 > 78.5
  for (int it = 0; it < 40; ++it) {
    const double mid = 0.5 * (lo + hi);
    const double x = px + mid * ux;
    const double y = py + mid * uy;
    if (std::hypot(x, y) < arenaRadius(std::atan2(y, x))) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

}  // namespace

std::vector<Scan> loadLog(const std::string& path, std::size_t stride, std::size_t max_scans) {
  const std::vector<wavog::CarmenScan> log = wavog::readCarmenLog(path);
  std::vector<Scan> scans;
  for (std::size_t i = 0; i < log.size(); i += stride) {
    if (max_scans != 0 && scans.size() >= max_scans) break;
    const wavog::CarmenScan& c = log[i];
    Scan s;
    s.pose = c.laser_pose;
    s.ranges = c.ranges;
    s.angle_min = c.angle_min;
    s.angle_increment = c.angle_increment;
    s.range_min = 0.0;
    s.range_max = c.range_max;
    scans.push_back(std::move(s));
  }
  return scans;
}

std::vector<Scan> syntheticLms291x4(int steps) {
  struct Mount {
    double x, y, yaw;
  };
  const Mount mounts[4] = {
      {1.0, 0.0, 0.0}, {-1.0, 0.0, M_PI}, {0.0, 0.5, M_PI / 2}, {0.0, -0.5, -M_PI / 2}};
  constexpr int kBeams = 361;
  const double increment = M_PI / 360.0;
  std::mt19937 rng(20070101);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<Scan> scans;
  for (int k = 0; k < steps; ++k) {
    const double t = 0.1 * k;
    const double vx = 0.5 * std::cos(0.5 * t);
    const double vy = 0.5 * std::sin(0.5 * t);
    const double vyaw = 0.05 * k;
    for (const Mount& m : mounts) {
      Scan s;
      s.pose.x = vx + std::cos(vyaw) * m.x - std::sin(vyaw) * m.y;
      s.pose.y = vy + std::sin(vyaw) * m.x + std::cos(vyaw) * m.y;
      s.pose.theta = vyaw + m.yaw;
      s.angle_min = -M_PI / 2;
      s.angle_increment = increment;
      s.range_min = 0.0;
      s.range_max = 80.0;
      s.ranges.resize(kBeams);
      for (int i = 0; i < kBeams; ++i) {
        const double a = s.pose.theta + s.angle_min + i * increment;
        const double r = castToArena(s.pose.x, s.pose.y, std::cos(a), std::sin(a)) + noise(rng);
        s.ranges[static_cast<std::size_t>(i)] = static_cast<float>(std::min(r, 79.99));
      }
      scans.push_back(std::move(s));
    }
  }
  return scans;
}

void forEachWorkload(const Options& opt, const std::function<void(const Workload&)>& run) {
  for (const std::string& w : opt.workloads) {
    std::vector<Scan> scans;
    std::string label;
    if (w == "fr079" || w == "csail") {
      const std::string file = w == "fr079" ? "fr079-corrected.log.gz" : "csail-robotlaser1.log.gz";
      const std::string path = (std::filesystem::path(opt.data_dir) / file).string();
      if (opt.data_dir.empty() || !std::ifstream(path).good()) {
        if (opt.smoke) {  // the smoke test must not depend on ../shared/data
          std::cerr << "wavog_compare: " << file << " not found; skipping " << w << "\n";
          continue;
        }
        throw std::runtime_error(file + " not found (data directory '" + opt.data_dir +
                                 "'; set WAVOG_DATA_DIR or --data)");
      }
      const std::size_t stride = w == "fr079" ? opt.stride_fr079 : opt.stride_csail;
      scans = loadLog(path, stride, opt.max_scans);
      label = w == "fr079" ? "fr079" : "csail";
      if (stride > 1) label += ", every " + std::to_string(stride) + "th scan";
    } else if (w == "lms291x4") {
      scans = syntheticLms291x4(opt.synthetic_steps);
      label = "4x LMS-291, 60-80 m (synthetic)";
    } else {
      throw std::invalid_argument("unknown workload " + w);
    }
    for (double res : opt.resolutions) {
      Workload wl;
      wl.name = w + "_" + std::to_string(std::lround(res * 100)) + "cm";
      wl.label = label;
      wl.resolution = res;
      wl.scans = scans;
      wl.timed_scans =
          opt.timed_scans == 0 ? scans.size() : std::min(opt.timed_scans, scans.size());
      std::cerr << wl.name << ": " << wl.scans.size() << " scans, " << wl.timed_scans
                << " timed per repetition" << std::endl;
      run(wl);
    }
  }
}

}  // namespace wavog_compare
