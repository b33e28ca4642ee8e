// wavog_compare: wavog_core (clamping and forgetting), OctoMap (OcTree::insertPointCloud) and the
// dense baseline grid, side by side in one process, on the same scans at the same resolution:
// speed (median scans/s over repetitions after a warm-up), memory (own account and resident-set
// growth, bytes per observed cell) and map agreement over the commonly observed cells, plus PNGs
// colouring the disagreeing cells. Single-threaded; run by `make compare` (issue 6).
#include <malloc.h>
#include <octomap/OcTree.h>
#include <sys/stat.h>
#include <sys/utsname.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <memory>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "tool_support.h"
#include "wavog_mapping/baseline/dense_grid.h"
#include "wavog_mapping/core/params.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/io/carmen_reader.h"
#include "wavog_mapping/io/image_io.h"

#ifndef WAVOG_SOURCE_DIR
#define WAVOG_SOURCE_DIR "."
#endif
#ifndef WAVOG_COMPARE_BUILD_TYPE
#define WAVOG_COMPARE_BUILD_TYPE "unknown"
#endif
#ifndef WAVOG_OCTOMAP_VERSION
#define WAVOG_OCTOMAP_VERSION "unknown"
#endif

namespace {

using Clock = std::chrono::steady_clock;

// ------------------------------------------------------------------------------------------------
// Workloads

/// One scan with its own storage.
struct Scan {
  wavog::Pose2 pose;  ///< laser pose, map frame
  std::vector<float> ranges;
  double angle_min = 0.0;
  double angle_increment = 0.0;
  double range_min = 0.0;
  double range_max = 0.0;
  wavog::ScanView view() const {
    return wavog::ScanView{ranges.data(),   ranges.size(), angle_min,
                           angle_increment, range_min,     range_max};
  }
};

struct Workload {
  std::string name;   ///< short name for files
  std::string label;  ///< table label
  double resolution = 0.05;
  std::vector<Scan> scans;
  std::size_t timed_scans = 0;  ///< scans per timed repetition (a prefix of `scans`)
};

/// Every `stride`-th scan of a log, up to `max_scans` scans (0: all).
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

/// Four LMS-291 (361 beams over 180 deg, 0.5 deg, range_max 80 m) on a vehicle that creeps and
/// turns in the middle of an open arena whose boundary lies 60-80 m away: every beam returns at
/// 60-80 m. Four scans per step (front, rear, left, right), 1 cm Gaussian range noise, fixed seed.
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

// ------------------------------------------------------------------------------------------------
// The structures under test, behind one small interface (one virtual call per scan, not per beam).

/// Per-cell class for agreement: unobserved, free (p < 0.5), occupied (p > 0.5), undecided.
enum Cls : std::uint8_t { kUnobs = 0, kFree = 1, kOcc = 2, kHalf = 3 };

Cls classOf(double log_odds) {
  if (log_odds > 0.0) return kOcc;
  if (log_odds < 0.0) return kFree;
  return kHalf;
}

class Subject {
 public:
  virtual ~Subject() = default;
  virtual void integrate(const Scan& scan) = 0;
  /// Bytes by the structure's own account.
  virtual std::size_t ownBytes() const = 0;
  /// Observed finest cells by the structure's own account.
  virtual std::uint64_t observedCells() const = 0;
  /// Class of every cell of `box` (row-major, x fastest).
  virtual std::vector<std::uint8_t> classify(const wavog::CellBox& box) const = 0;
  /// Work done so far by the structure's own count (nodes visited, cells updated); 0 if unknown.
  std::uint64_t work() const { return work_; }

 protected:
  std::uint64_t work_ = 0;
};

class WavogSubject : public Subject {
 public:
  explicit WavogSubject(const wavog::MapParams& params) : map_(params) {}
  void integrate(const Scan& scan) override {
    work_ += map_.integrate(scan.pose, scan.view()).nodes_visited;
  }
  std::size_t ownBytes() const override { return map_.stats().bytes; }
  std::uint64_t observedCells() const override { return map_.stats(true).observed_cells; }
  std::vector<std::uint8_t> classify(const wavog::CellBox& box) const override {
    const wavog::Raster r = map_.exportScale(0, box, wavog::Aggregation::kMean);
    std::vector<std::uint8_t> out(r.log_odds.size(), kUnobs);
    for (std::size_t i = 0; i < out.size(); ++i) {
      if (r.known[i] != 0) out[i] = classOf(r.log_odds[i]);
    }
    return out;
  }

 private:
  wavog::WaveletMap map_;
};

/// OctoMap as octomap_server uses it: one insertPointCloud per scan of the beam end points at
/// z = 0, sensor origin, maxrange = the no-return clearing distance (no-return beams are put beyond
/// it, so OctoMap clears free space up to maxrange and marks no hit).
class OctoMapSubject : public Subject {
 public:
  OctoMapSubject(double resolution, double no_return_clear)
      : tree_(resolution), clear_(no_return_clear) {
    tree_.setProbHit(0.7);
    tree_.setProbMiss(0.4);
    tree_.setClampingThresMin(0.12);
    tree_.setClampingThresMax(0.97);
  }
  void integrate(const Scan& scan) override {
    cloud_.clear();
    cloud_.reserve(scan.ranges.size());
    const double c = std::cos(scan.pose.theta);
    const double s = std::sin(scan.pose.theta);
    for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
      const double r = static_cast<double>(scan.ranges[i]);
      if (std::isnan(r) || r <= 0.0 || r < scan.range_min) continue;  // REP 117: invalid
      double length = r;
      if (r >= scan.range_max) {  // no return (+inf included)
        if (!(clear_ > 0.0)) continue;
        length = clear_ + 1.0;  // beyond maxrange: OctoMap clears up to maxrange, no hit
      }
      const double a = scan.angle_min + static_cast<double>(i) * scan.angle_increment;
      const double ca = std::cos(a);
      const double sa = std::sin(a);
      cloud_.push_back(static_cast<float>(scan.pose.x + length * (c * ca - s * sa)),
                       static_cast<float>(scan.pose.y + length * (s * ca + c * sa)), 0.0f);
    }
    const octomap::point3d origin(static_cast<float>(scan.pose.x), static_cast<float>(scan.pose.y),
                                  0.0f);
    tree_.insertPointCloud(cloud_, origin, clear_ > 0.0 ? clear_ : -1.0, false, false);
  }
  std::size_t ownBytes() const override { return tree_.memoryUsage(); }
  std::uint64_t observedCells() const override {
    std::uint64_t cells = 0;
    forEachLeafInLayer([&cells](std::int64_t, std::int64_t, std::int64_t n, double) {
      cells += static_cast<std::uint64_t>(n * n);
    });
    return cells;
  }
  std::vector<std::uint8_t> classify(const wavog::CellBox& box) const override {
    std::vector<std::uint8_t> out(static_cast<std::size_t>(box.width() * box.height()), kUnobs);
    forEachLeafInLayer([&](std::int64_t x0, std::int64_t y0, std::int64_t n, double lo) {
      for (std::int64_t y = std::max(y0, box.min_y); y < std::min(y0 + n, box.max_y); ++y) {
        for (std::int64_t x = std::max(x0, box.min_x); x < std::min(x0 + n, box.max_x); ++x) {
          out[static_cast<std::size_t>((y - box.min_y) * box.width() + (x - box.min_x))] =
              classOf(lo);
        }
      }
    });
    return out;
  }

 private:
  /// Calls f(min cell x, min cell y, cells per side, log-odds) for every leaf covering the z = 0
  /// layer (key 2^15 along z). The scans never leave that layer, so leaves are single cells unless
  /// OctoMap pruned them.
  template <typename F>
  void forEachLeafInLayer(F f) const {
    const unsigned max_depth = tree_.getTreeDepth();
    const std::int64_t half = std::int64_t{1} << (max_depth - 1);  // key of coordinate 0
    for (auto it = tree_.begin_leafs(), end = tree_.end_leafs(); it != end; ++it) {
      const std::int64_t n = std::int64_t{1} << (max_depth - it.getDepth());
      const octomap::OcTreeKey& key = it.getIndexKey();  // smallest key the leaf covers
      const std::int64_t kz = key[2];
      if (half < kz || half >= kz + n) continue;
      f(static_cast<std::int64_t>(key[0]) - half, static_cast<std::int64_t>(key[1]) - half, n,
        static_cast<double>(it->getLogOdds()));
    }
  }

  octomap::OcTree tree_;
  double clear_;
  octomap::Pointcloud cloud_;
};

class DenseSubject : public Subject {
 public:
  DenseSubject(const wavog::baseline::DenseGridParams& params, const wavog::CellBox& presize)
      : grid_(params) {
    grid_.reserve(presize);
  }
  wavog::CellBox extent() const { return grid_.extent(); }
  void integrate(const Scan& scan) override {
    work_ += grid_.integrate(scan.pose, scan.view()).cells_updated;
  }
  std::size_t ownBytes() const override { return grid_.bytes(); }
  std::uint64_t observedCells() const override { return grid_.countObserved(); }
  std::vector<std::uint8_t> classify(const wavog::CellBox& box) const override {
    std::vector<std::uint8_t> out(static_cast<std::size_t>(box.width() * box.height()), kUnobs);
    std::size_t i = 0;
    for (std::int64_t y = box.min_y; y < box.max_y; ++y) {
      for (std::int64_t x = box.min_x; x < box.max_x; ++x, ++i) {
        const std::int16_t v = grid_.rawValue(x, y);
        if (v != wavog::baseline::DenseGrid::kUnknown) out[i] = classOf(static_cast<double>(v));
      }
    }
    return out;
  }
  /// Bounding box of the observed cells (empty if none).
  wavog::CellBox observedBox() const {
    const wavog::CellBox e = grid_.extent();
    wavog::CellBox b{e.max_x, e.max_y, e.min_x, e.min_y};
    for (std::int64_t y = e.min_y; y < e.max_y; ++y) {
      for (std::int64_t x = e.min_x; x < e.max_x; ++x) {
        if (grid_.rawValue(x, y) == wavog::baseline::DenseGrid::kUnknown) continue;
        b.min_x = std::min(b.min_x, x);
        b.max_x = std::max(b.max_x, x + 1);
        b.min_y = std::min(b.min_y, y);
        b.max_y = std::max(b.max_y, y + 1);
      }
    }
    return b;
  }

 private:
  wavog::baseline::DenseGrid grid_;
};

// ------------------------------------------------------------------------------------------------
// Measurement

std::size_t residentBytes() {
  std::ifstream statm("/proc/self/statm");
  std::size_t size = 0, resident = 0;
  statm >> size >> resident;
  return resident * static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

/// CPU time consumed by the calling thread (s), user + system: unlike wall-clock time it does not
/// count the time the thread waits for a core that other processes hold.
double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

enum SubjectId { kWavogClamp = 0, kWavogForget = 1, kOctoMap = 2, kDense = 3, kSubjects = 4 };
const char* const kSubjectNames[kSubjects] = {"wavog-clamp", "wavog-forget", "OctoMap", "dense"};

struct SubjectResult {
  double scans_per_s = 0.0;         ///< by the median thread CPU time of the repetitions
  double scans_per_s_wall = 0.0;    ///< by the median wall-clock time of the repetitions
  double min_s = 0.0, max_s = 0.0;  ///< spread of the repetition CPU times (s)
  std::vector<double> rep_seconds;  ///< thread CPU time of each repetition (s)
  std::vector<double> rep_wall;     ///< wall-clock time of each repetition (s)
  double warmup_s = 0.0;            ///< the warm-up run (all scans)
  std::size_t own_bytes = 0;
  std::size_t rss_growth = 0;
  std::uint64_t observed = 0;
  double work_per_scan = 0.0;  ///< nodes visited / cells updated per scan (warm-up run)
};

struct PairAgreement {
  std::uint64_t common = 0;  ///< cells observed by wavog (this variant), OctoMap and dense
  std::uint64_t same = 0;
  std::uint64_t a_occ_b_free = 0;
  std::uint64_t a_free_b_occ = 0;
  std::uint64_t undecided = 0;  ///< one side exactly at p = 0.5
  double share() const {
    return common == 0 ? 0.0 : static_cast<double>(same) / static_cast<double>(common);
  }
};

struct WorkloadResult {
  std::string label;
  std::string name;
  double resolution = 0.0;
  std::size_t scans = 0;
  std::size_t timed_scans = 0;
  int reps = 0;
  SubjectResult subject[kSubjects];
  PairAgreement clamp_octomap, clamp_dense, octomap_dense, forget_octomap, forget_dense;
  std::vector<std::string> pictures;
};

struct Options {
  std::string data_dir;
  std::string out_dir = "compare_output";
  std::vector<std::string> workloads = {"fr079", "csail", "lms291x4"};
  std::vector<double> resolutions = {0.05, 0.10};
  int reps = 5;
  std::size_t max_scans = 0;
  std::size_t stride_fr079 = 1;
  std::size_t stride_csail = 1;
  std::size_t timed_scans = 0;
  int synthetic_steps = 25;
  double no_return_clear = 80.0;
  int crop_cells = 200;
  bool smoke = false;
  std::string command;
};

PairAgreement agreement(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b,
                        const std::vector<std::uint8_t>& c1, const std::vector<std::uint8_t>& c2) {
  PairAgreement p;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i] == kUnobs || b[i] == kUnobs || c1[i] == kUnobs || c2[i] == kUnobs) continue;
    ++p.common;
    if (a[i] == b[i]) {
      ++p.same;
    } else if (a[i] == kOcc && b[i] == kFree) {
      ++p.a_occ_b_free;
    } else if (a[i] == kFree && b[i] == kOcc) {
      ++p.a_free_b_occ;
    } else {
      ++p.undecided;
    }
  }
  return p;
}

void makeDirs(const std::string& path) {
  std::string partial;
  std::stringstream ss(path);
  std::string part;
  if (!path.empty() && path[0] == '/') partial = "/";
  while (std::getline(ss, part, '/')) {
    if (part.empty()) continue;
    partial += part + "/";
    mkdir(partial.c_str(), 0755);
  }
}

/// Colours of the disagreement pictures.
const wavog::Rgb kColUnobserved{200, 215, 235};  // observed by none: pale blue
const wavog::Rgb kColPartly{170, 170, 170};      // observed by some, not all three: grey
const wavog::Rgb kColFree{255, 255, 255};        // both free
const wavog::Rgb kColOcc{0, 0, 0};               // both occupied
const wavog::Rgb kColWavogOcc{230, 30, 30};      // wavog occupied, other free: red
const wavog::Rgb kColWavogFree{30, 90, 230};     // wavog free, other occupied: blue
const wavog::Rgb kColHalf{240, 180, 0};          // one side at exactly p = 0.5: amber

wavog::Image disagreementImage(const std::vector<std::uint8_t>& a,
                               const std::vector<std::uint8_t>& b,
                               const std::vector<std::uint8_t>& all3, const wavog::CellBox& box,
                               const wavog::CellBox& crop, int upscale) {
  const int w = static_cast<int>(crop.width());
  const int h = static_cast<int>(crop.height());
  wavog::Image img(w * upscale, h * upscale, 3);
  for (int row = 0; row < h; ++row) {
    const std::int64_t y = crop.max_y - 1 - row;  // north up
    for (int col = 0; col < w; ++col) {
      const std::int64_t x = crop.min_x + col;
      wavog::Rgb colour = kColUnobserved;
      if (x >= box.min_x && x < box.max_x && y >= box.min_y && y < box.max_y) {
        const std::size_t i =
            static_cast<std::size_t>((y - box.min_y) * box.width() + (x - box.min_x));
        if (all3[i] == 0) {
          colour = (a[i] != kUnobs || b[i] != kUnobs) ? kColPartly : kColUnobserved;
        } else if (a[i] == b[i]) {
          colour = a[i] == kOcc ? kColOcc : (a[i] == kFree ? kColFree : kColHalf);
        } else if (a[i] == kOcc && b[i] == kFree) {
          colour = kColWavogOcc;
        } else if (a[i] == kFree && b[i] == kOcc) {
          colour = kColWavogFree;
        } else {
          colour = kColHalf;
        }
      }
      for (int dy = 0; dy < upscale; ++dy) {
        for (int dx = 0; dx < upscale; ++dx) {
          std::uint8_t* p = img.at(col * upscale + dx, row * upscale + dy);
          p[0] = colour.r;
          p[1] = colour.g;
          p[2] = colour.b;
        }
      }
    }
  }
  return img;
}

/// The crop_cells x crop_cells window (inside box) holding the most disagreeing cells.
wavog::CellBox densestDisagreement(const std::vector<std::uint8_t>& a,
                                   const std::vector<std::uint8_t>& b,
                                   const std::vector<std::uint8_t>& all3, const wavog::CellBox& box,
                                   std::int64_t crop) {
  const std::int64_t w = box.width();
  const std::int64_t h = box.height();
  crop = std::min({crop, w, h});
  // Summed-area table of disagreement indicators.
  std::vector<std::int64_t> sat(static_cast<std::size_t>((w + 1) * (h + 1)), 0);
  for (std::int64_t y = 0; y < h; ++y) {
    for (std::int64_t x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y * w + x);
      const std::int64_t d = (all3[i] != 0 && a[i] != b[i]) ? 1 : 0;
      sat[static_cast<std::size_t>((y + 1) * (w + 1) + x + 1)] =
          d + sat[static_cast<std::size_t>(y * (w + 1) + x + 1)] +
          sat[static_cast<std::size_t>((y + 1) * (w + 1) + x)] -
          sat[static_cast<std::size_t>(y * (w + 1) + x)];
    }
  }
  std::int64_t best = -1, bx = 0, by = 0;
  const std::int64_t stride = std::max<std::int64_t>(1, crop / 8);
  for (std::int64_t y = 0; y + crop <= h; y += stride) {
    for (std::int64_t x = 0; x + crop <= w; x += stride) {
      const auto at = [&](std::int64_t xx, std::int64_t yy) {
        return sat[static_cast<std::size_t>(yy * (w + 1) + xx)];
      };
      const std::int64_t s = at(x + crop, y + crop) - at(x, y + crop) - at(x + crop, y) + at(x, y);
      if (s > best) {
        best = s;
        bx = x;
        by = y;
      }
    }
  }
  return wavog::CellBox{box.min_x + bx, box.min_y + by, box.min_x + bx + crop,
                        box.min_y + by + crop};
}

/// Runs every structure on one workload.
WorkloadResult runWorkload(const Workload& wl, const Options& opt) {
  WorkloadResult res;
  res.label = wl.label;
  res.name = wl.name;
  res.resolution = wl.resolution;
  res.scans = wl.scans.size();
  res.timed_scans = wl.timed_scans;
  res.reps = opt.reps;

  wavog::MapParams clamp = wavog::MapParams::defaultsFor(wavog::PolicyType::kClamp);
  clamp.grid.resolution = wl.resolution;
  clamp.sensor.no_return_clear = opt.no_return_clear;
  wavog::MapParams forget = wavog::MapParams::defaultsFor(wavog::PolicyType::kForget);
  forget.grid.resolution = wl.resolution;
  forget.sensor.no_return_clear = opt.no_return_clear;
  wavog::baseline::DenseGridParams dense;
  dense.resolution = wl.resolution;
  dense.hit_log_odds = clamp.sensor.odd_occ;
  dense.miss_log_odds = clamp.sensor.odd_emp;
  dense.clamp_min_log_odds = clamp.policy.clamp_min;
  dense.clamp_max_log_odds = clamp.policy.clamp_max;
  dense.no_return_clear_m = opt.no_return_clear;

  // The warm-up grows the dense grid as scans arrive; the timed runs get it pre-sized to that
  // extent (allocation untimed, like the other structures' construction), its best case.
  wavog::CellBox dense_presize;
  const std::function<std::unique_ptr<Subject>()> make[kSubjects] = {
      [&] { return std::unique_ptr<Subject>(new WavogSubject(clamp)); },
      [&] { return std::unique_ptr<Subject>(new WavogSubject(forget)); },
      [&] {
        return std::unique_ptr<Subject>(new OctoMapSubject(wl.resolution, opt.no_return_clear));
      },
      [&] { return std::unique_ptr<Subject>(new DenseSubject(dense, dense_presize)); },
  };

  std::unique_ptr<Subject> full[kSubjects];
  for (int k = 0; k < kSubjects; ++k) {
    SubjectResult& r = res.subject[k];
    // Warm-up: the whole workload into a fresh structure. Its map is the one compared, and the
    // growth of the resident set during it is the RSS memory figure (freed heap returned first).
    malloc_trim(0);
    const std::size_t rss0 = residentBytes();
    full[k] = make[k]();
    const auto t0 = Clock::now();
    for (const Scan& s : wl.scans) full[k]->integrate(s);
    const auto t1 = Clock::now();
    r.warmup_s = seconds(t0, t1);
    r.rss_growth = residentBytes() - std::min(rss0, residentBytes());
    r.own_bytes = full[k]->ownBytes();
    r.observed = full[k]->observedCells();
    r.work_per_scan = static_cast<double>(full[k]->work()) / static_cast<double>(wl.scans.size());
  }
  dense_presize = static_cast<const DenseSubject&>(*full[kDense]).extent();
  // Timed repetitions, each into a fresh structure (construction and destruction not timed).
  // The structures take turns within each repetition, so a burst of load from other processes
  // on a shared machine lands on all of them rather than on one.
  for (int rep = 0; rep < opt.reps; ++rep) {
    for (int k = 0; k < kSubjects; ++k) {
      std::unique_ptr<Subject> m = make[k]();
      const auto a = Clock::now();
      const double ca = threadCpuSeconds();
      for (std::size_t i = 0; i < wl.timed_scans; ++i) m->integrate(wl.scans[i]);
      const double cb = threadCpuSeconds();
      const auto b = Clock::now();
      res.subject[k].rep_seconds.push_back(cb - ca);
      res.subject[k].rep_wall.push_back(seconds(a, b));
    }
  }
  for (int k = 0; k < kSubjects; ++k) {
    SubjectResult& r = res.subject[k];
    r.scans_per_s = static_cast<double>(wl.timed_scans) / median(r.rep_seconds);
    r.scans_per_s_wall = static_cast<double>(wl.timed_scans) / median(r.rep_wall);
    r.min_s = *std::min_element(r.rep_seconds.begin(), r.rep_seconds.end());
    r.max_s = *std::max_element(r.rep_seconds.begin(), r.rep_seconds.end());
    std::cerr << "  " << std::setw(12) << kSubjectNames[k] << ": " << std::fixed
              << std::setprecision(1) << r.scans_per_s << " scans/s (warm-up "
              << std::setprecision(2) << r.warmup_s << " s), " << r.own_bytes << " B own, "
              << r.rss_growth << " B RSS, " << r.observed << " observed cells" << std::endl;
  }

  // Agreement over the cells all three kinds observed, inside the dense grid's observed box.
  const wavog::CellBox box = static_cast<const DenseSubject&>(*full[kDense]).observedBox();
  if (box.empty()) return res;
  std::vector<std::uint8_t> cls[kSubjects];
  for (int k = 0; k < kSubjects; ++k) cls[k] = full[k]->classify(box);
  res.clamp_octomap = agreement(cls[kWavogClamp], cls[kOctoMap], cls[kDense], cls[kDense]);
  res.clamp_dense = agreement(cls[kWavogClamp], cls[kDense], cls[kOctoMap], cls[kOctoMap]);
  res.octomap_dense = agreement(cls[kOctoMap], cls[kDense], cls[kWavogClamp], cls[kWavogClamp]);
  res.forget_octomap = agreement(cls[kWavogForget], cls[kOctoMap], cls[kDense], cls[kDense]);
  res.forget_dense = agreement(cls[kWavogForget], cls[kDense], cls[kOctoMap], cls[kOctoMap]);

  // Pictures: cells observed by all three; disagreements of wavog-clamp against each other map.
  std::vector<std::uint8_t> all3(cls[kDense].size(), 0);
  for (std::size_t i = 0; i < all3.size(); ++i) {
    all3[i] =
        (cls[kWavogClamp][i] != kUnobs && cls[kOctoMap][i] != kUnobs && cls[kDense][i] != kUnobs)
            ? 1
            : 0;
  }
  const std::string stem = opt.out_dir + "/disagree_" + wl.name;
  const struct {
    int other;
    const char* suffix;
  } pairs[2] = {{kOctoMap, "octomap"}, {kDense, "dense"}};
  for (const auto& pr : pairs) {
    const std::string full_path = stem + "_vs_" + pr.suffix + ".png";
    wavog::writePng(full_path,
                    disagreementImage(cls[kWavogClamp], cls[pr.other], all3, box, box, 1));
    res.pictures.push_back(full_path);
    const wavog::CellBox crop =
        densestDisagreement(cls[kWavogClamp], cls[pr.other], all3, box, opt.crop_cells);
    const std::string crop_path = stem + "_vs_" + pr.suffix + "_zoom.png";
    wavog::writePng(crop_path,
                    disagreementImage(cls[kWavogClamp], cls[pr.other], all3, box, crop, 3));
    res.pictures.push_back(crop_path);
  }
  return res;
}

// ------------------------------------------------------------------------------------------------
// Reporting

std::string fmt(double v, int precision) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(precision) << v;
  return os.str();
}

std::string pct(const PairAgreement& p) {
  return p.common == 0 ? "n/a" : fmt(100.0 * p.share(), 2) + " %";
}

double perCell(std::size_t bytes, std::uint64_t cells) {
  return cells == 0 ? 0.0 : static_cast<double>(bytes) / static_cast<double>(cells);
}

std::string readFirstLine(const std::string& path, const std::string& key) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.compare(0, key.size(), key) == 0) {
      const std::size_t colon = line.find(':');
      std::string v = colon == std::string::npos ? line : line.substr(colon + 1);
      const std::size_t start = v.find_first_not_of(" \t");
      return start == std::string::npos ? v : v.substr(start);
    }
  }
  return "unknown";
}

/// Commit of the source tree (with "+dirty" when it has local changes), or "unknown".
std::string sourceCommit() {
  const std::string cmd = std::string("git -C '") + WAVOG_SOURCE_DIR +
                          "' describe --always --dirty=+dirty --abbrev=10 2>/dev/null";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (pipe == nullptr) return "unknown";
  char buf[128] = {0};
  std::string out = fgets(buf, sizeof(buf), pipe) != nullptr ? std::string(buf) : "";
  pclose(pipe);
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out.empty() ? "unknown" : out;
}

std::string machineDescription() {
  std::ostringstream os;
  utsname u{};
  uname(&u);
  double load[3] = {0, 0, 0};
  getloadavg(load, 3);
  const std::time_t now = std::time(nullptr);
  char when[64];
  std::strftime(when, sizeof(when), "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  os << "- CPU: " << readFirstLine("/proc/cpuinfo", "model name") << ", "
     << sysconf(_SC_NPROCESSORS_ONLN) << " logical cores online; memory "
     << readFirstLine("/proc/meminfo", "MemTotal") << "\n"
     << "- OS: " << u.sysname << " " << u.release << " (" << u.machine << "), "
     << readFirstLine("/etc/os-release", "PRETTY_NAME") << "\n"
     << "- Compiler: GCC " << __VERSION__ << ", build type " << WAVOG_COMPARE_BUILD_TYPE
     << ", no -march=native; OctoMap " << WAVOG_OCTOMAP_VERSION << " (Debian liboctomap-dev)\n"
     << "- Source: commit " << sourceCommit() << "\n"
     << "- Run: " << when << ", load average at the end " << fmt(load[0], 2) << " / "
     << fmt(load[1], 2) << " / " << fmt(load[2], 2) << " (1/5/15 min)\n";
  return os.str();
}

std::string report(const std::vector<WorkloadResult>& results, const Options& opt) {
  std::ostringstream os;
  os << "### Speed (scans/s by thread CPU time, median of " << opt.reps
     << " repetitions after a warm-up)\n\n"
     << "| workload | res | scans timed | wavog-clamp | wavog-forget | OctoMap | dense | "
        "clamp/OctoMap | clamp/dense | forget/OctoMap | forget/dense |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const WorkloadResult& r : results) {
    const SubjectResult* s = r.subject;
    os << "| " << r.label << " | " << fmt(r.resolution * 100, 0) << " cm | " << r.timed_scans
       << (r.timed_scans < r.scans ? " of " + std::to_string(r.scans) : "") << " | "
       << fmt(s[kWavogClamp].scans_per_s, 0) << " | " << fmt(s[kWavogForget].scans_per_s, 0)
       << " | " << fmt(s[kOctoMap].scans_per_s, 1) << " | " << fmt(s[kDense].scans_per_s, 0)
       << " | " << fmt(s[kWavogClamp].scans_per_s / s[kOctoMap].scans_per_s, 1) << "x | "
       << fmt(s[kWavogClamp].scans_per_s / s[kDense].scans_per_s, 2) << "x | "
       << fmt(s[kWavogForget].scans_per_s / s[kOctoMap].scans_per_s, 1) << "x | "
       << fmt(s[kWavogForget].scans_per_s / s[kDense].scans_per_s, 2) << "x |\n";
  }
  os << "\nWork per scan (warm-up run): wavog nodes and finest cells visited (IntegrateStats::"
        "nodes_visited), dense cells updated.\n\n"
     << "| workload | res | wavog-clamp visits | wavog-forget visits | dense cells updated |\n"
     << "|---|---|---|---|---|\n";
  for (const WorkloadResult& r : results) {
    os << "| " << r.label << " | " << fmt(r.resolution * 100, 0) << " cm | "
       << fmt(r.subject[kWavogClamp].work_per_scan, 0) << " | "
       << fmt(r.subject[kWavogForget].work_per_scan, 0) << " | "
       << fmt(r.subject[kDense].work_per_scan, 0) << " |\n";
  }
  os << "\n### Memory (bytes per observed cell: own account / resident-set growth)\n\n"
     << "| workload | res | observed cells (clamp / OctoMap / dense) | own MB (clamp / forget / "
        "OctoMap / dense) | wavog-clamp | wavog-forget | OctoMap | dense | OctoMap/clamp (own) |\n"
     << "|---|---|---|---|---|---|---|---|---|\n";
  for (const WorkloadResult& r : results) {
    const SubjectResult* s = r.subject;
    os << "| " << r.label << " | " << fmt(r.resolution * 100, 0) << " cm | "
       << s[kWavogClamp].observed << " / " << s[kOctoMap].observed << " / " << s[kDense].observed
       << " | " << fmt(s[kWavogClamp].own_bytes / 1e6, 2) << " / "
       << fmt(s[kWavogForget].own_bytes / 1e6, 2) << " / " << fmt(s[kOctoMap].own_bytes / 1e6, 2)
       << " / " << fmt(s[kDense].own_bytes / 1e6, 2) << " |";
    for (int k = 0; k < kSubjects; ++k) {
      os << " " << fmt(perCell(s[k].own_bytes, s[k].observed), 2) << " / "
         << fmt(perCell(s[k].rss_growth, s[k].observed), 2) << " |";
    }
    os << " "
       << fmt(perCell(s[kOctoMap].own_bytes, s[kOctoMap].observed) /
                  perCell(s[kWavogClamp].own_bytes, s[kWavogClamp].observed),
              1)
       << "x |\n";
  }
  os << "\nObserved cells are each structure's own count: wavog's sector model observes the whole "
        "field of view, rays only the cells they cross (fewer at long range).\n";
  os << "\n### Agreement (same class, occupied p > 0.5 / free p < 0.5, among cells all three "
        "observed)\n\n"
     << "| workload | res | common cells | clamp~OctoMap | clamp~dense | OctoMap~dense | "
        "forget~OctoMap | forget~dense | clamp occ / OctoMap free | clamp free / OctoMap occ | "
        "clamp occ / dense free | clamp free / dense occ |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const WorkloadResult& r : results) {
    os << "| " << r.label << " | " << fmt(r.resolution * 100, 0) << " cm | "
       << r.clamp_octomap.common << " | " << pct(r.clamp_octomap) << " | " << pct(r.clamp_dense)
       << " | " << pct(r.octomap_dense) << " | " << pct(r.forget_octomap) << " | "
       << pct(r.forget_dense) << " | " << r.clamp_octomap.a_occ_b_free << " | "
       << r.clamp_octomap.a_free_b_occ << " | " << r.clamp_dense.a_occ_b_free << " | "
       << r.clamp_dense.a_free_b_occ << " |\n";
  }
  os << "\n### Targets (issue 6; wavog-clamp unless stated)\n\n";
  const auto find = [&results](const std::string& name, double res) -> const WorkloadResult* {
    for (const WorkloadResult& r : results) {
      if (r.name.rfind(name, 0) == 0 && std::abs(r.resolution - res) < 1e-9) return &r;
    }
    return nullptr;
  };
  const auto verdict = [](bool ok) { return ok ? "**met**" : "**not met**"; };
  if (const WorkloadResult* r = find("fr079", 0.05)) {
    const double x = r->subject[kWavogClamp].scans_per_s / r->subject[kOctoMap].scans_per_s;
    os << "- >= 30x OctoMap on fr079 at 5 cm: " << fmt(x, 1) << "x, " << verdict(x >= 30) << "\n";
    const double d = r->subject[kWavogClamp].scans_per_s / r->subject[kDense].scans_per_s;
    os << "- within 2x of dense on fr079 at 5 cm: wavog/dense " << fmt(d, 2) << "x, "
       << verdict(d >= 0.5) << "\n";
  }
  if (const WorkloadResult* r = find("lms291x4", 0.05)) {
    const double x = r->subject[kWavogClamp].scans_per_s / r->subject[kOctoMap].scans_per_s;
    os << "- >= 100x OctoMap on the 80 m workload at 5 cm: " << fmt(x, 1) << "x, "
       << verdict(x >= 100) << "\n";
  }
  for (const WorkloadResult& r : results) {
    if (r.name.rfind("lms291x4", 0) != 0) continue;
    const double d = r.subject[kWavogClamp].scans_per_s / r.subject[kDense].scans_per_s;
    os << "- at least as fast as dense on the 80 m workload at " << fmt(r.resolution * 100, 0)
       << " cm: " << fmt(d, 2) << "x, " << verdict(d >= 1.0) << "\n";
  }
  for (const WorkloadResult& r : results) {
    const double o = perCell(r.subject[kOctoMap].own_bytes, r.subject[kOctoMap].observed);
    const double w = perCell(r.subject[kWavogClamp].own_bytes, r.subject[kWavogClamp].observed);
    os << "- <= 1/40 of OctoMap's bytes per observed cell, " << r.label << " "
       << fmt(r.resolution * 100, 0) << " cm: " << fmt(w, 3) << " vs " << fmt(o, 2) << " B (1/"
       << fmt(o / w, 1) << "), " << verdict(w * 40 <= o) << "\n";
  }
  for (const WorkloadResult& r : results) {
    os << "- >= 95 % agreement, " << r.label << " " << fmt(r.resolution * 100, 0)
       << " cm: with OctoMap " << pct(r.clamp_octomap) << ", with dense " << pct(r.clamp_dense)
       << ", " << verdict(r.clamp_octomap.share() >= 0.95 && r.clamp_dense.share() >= 0.95) << "\n";
  }
  os << "\n### Repetition times (thread CPU s: min / median / max; wall-clock median)\n\n"
     << "| workload | res | wavog-clamp | wavog-forget | OctoMap | dense | CPU share | "
        "clamp/OctoMap wall | clamp/dense wall |\n|---|---|---|---|---|---|---|---|---|\n";
  for (const WorkloadResult& r : results) {
    os << "| " << r.label << " | " << fmt(r.resolution * 100, 0) << " cm |";
    double cpu = 0.0, wall = 0.0;
    for (int k = 0; k < kSubjects; ++k) {
      const SubjectResult& s = r.subject[k];
      os << " " << fmt(s.min_s, 3) << " / " << fmt(median(s.rep_seconds), 3) << " / "
         << fmt(s.max_s, 3) << "; " << fmt(median(s.rep_wall), 3) << " |";
      for (double v : s.rep_seconds) cpu += v;
      for (double v : s.rep_wall) wall += v;
    }
    const SubjectResult* s = r.subject;
    os << " " << fmt(wall > 0 ? 100.0 * cpu / wall : 0.0, 0) << " % | "
       << fmt(s[kWavogClamp].scans_per_s_wall / s[kOctoMap].scans_per_s_wall, 1) << "x | "
       << fmt(s[kWavogClamp].scans_per_s_wall / s[kDense].scans_per_s_wall, 2) << "x |\n";
  }
  os << "\nCPU share: thread CPU time over wall-clock time of all timed runs (below 100 % when "
        "other processes held the cores).\n";
  os << "\nMachine:\n\n" << machineDescription() << "\nCommand: `" << opt.command << "`\n";
  return os.str();
}

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

void usage() {
  std::cout
      << "usage: wavog_compare [options]\n"
         "  --workloads LIST      fr079,csail,lms291x4 (default: all three)\n"
         "  --resolutions LIST    cell sizes in m (default 0.05,0.1)\n"
         "  --reps N              timed repetitions after the warm-up, >= 1 (default 5)\n"
         "  --max-scans N         scans taken from each log, 0 = all (default 0)\n"
         "  --stride LIST         take every N-th scan of a log, e.g. fr079=8,csail=14 (default "
         "1)\n"
         "  --timed-scans N       scans per timed repetition (a prefix), 0 = all (default 0)\n"
         "  --synthetic-steps N   steps of the four-LMS-291 workload, 4 scans each (default 25)\n"
         "  --no-return-clear M   no-return beams clear free space up to M metres, 0 = not at all\n"
         "                        (default 80; OctoMap's maxrange)\n"
         "  --crop N              cells per side of the zoomed disagreement pictures (default "
         "200)\n"
         "  --data DIR            directory of the CARMEN logs (default: found from "
         "../shared/data)\n"
         "  --out DIR             output directory (default compare_output)\n"
         "  --smoke               tiny workload, 1 repetition: a test that the program runs\n";
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  for (int i = 0; i < argc; ++i) opt.command += (i ? " " : "") + std::string(argv[i]);
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      const auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
        return argv[++i];
      };
      if (a == "--workloads") {
        opt.workloads = splitList(value());
      } else if (a == "--resolutions") {
        opt.resolutions.clear();
        for (const std::string& r : splitList(value())) {
          opt.resolutions.push_back(wavog_tools::parseNumber(a, r.c_str()));
        }
      } else if (a == "--reps") {
        opt.reps = static_cast<int>(wavog_tools::parseInteger(a, value().c_str(), 1));
      } else if (a == "--max-scans") {
        opt.max_scans = static_cast<std::size_t>(wavog_tools::parseInteger(a, value().c_str(), 0));
      } else if (a == "--stride") {
        for (const std::string& item : splitList(value())) {
          const std::size_t eq = item.find('=');
          const std::string key = item.substr(0, eq);
          const std::size_t n = eq == std::string::npos
                                    ? 0
                                    : static_cast<std::size_t>(wavog_tools::parseInteger(
                                          a, item.substr(eq + 1).c_str(), 1));
          if (n == 0 || (key != "fr079" && key != "csail")) {
            throw std::invalid_argument("--stride takes fr079=N,csail=N with N >= 1");
          }
          (key == "fr079" ? opt.stride_fr079 : opt.stride_csail) = n;
        }
      } else if (a == "--timed-scans") {
        opt.timed_scans =
            static_cast<std::size_t>(wavog_tools::parseInteger(a, value().c_str(), 0));
      } else if (a == "--synthetic-steps") {
        opt.synthetic_steps = static_cast<int>(wavog_tools::parseInteger(a, value().c_str(), 1));
      } else if (a == "--no-return-clear") {
        opt.no_return_clear = wavog_tools::parseNumber(a, value().c_str());
      } else if (a == "--crop") {
        opt.crop_cells = static_cast<int>(wavog_tools::parseInteger(a, value().c_str(), 1));
      } else if (a == "--data") {
        opt.data_dir = value();
      } else if (a == "--out") {
        opt.out_dir = value();
      } else if (a == "--smoke") {
        opt.smoke = true;
      } else if (a == "--help" || a == "-h") {
        usage();
        return 0;
      } else {
        throw std::invalid_argument("unknown option " + a);
      }
    }
    if (opt.reps < 1 || opt.synthetic_steps < 1 || opt.no_return_clear < 0 || opt.crop_cells < 8) {
      throw std::invalid_argument(
          "--reps, --synthetic-steps >= 1, --no-return-clear >= 0, --crop >= 8");
    }
  } catch (const std::exception& e) {
    std::cerr << "wavog_compare: " << e.what() << "\n";
    usage();
    return 2;
  }
  if (opt.smoke) {
    opt.reps = 1;
    opt.resolutions = {0.2};
    opt.synthetic_steps = 1;
    opt.max_scans = 10;
    opt.crop_cells = 32;
  }
  if (opt.data_dir.empty()) opt.data_dir = wavog::findDataDir(WAVOG_SOURCE_DIR);
  makeDirs(opt.out_dir);

  std::vector<WorkloadResult> results;
  try {
    for (const std::string& w : opt.workloads) {
      std::vector<Scan> scans;
      std::string label;
      if (w == "fr079" || w == "csail") {
        const std::string file =
            w == "fr079" ? "fr079-corrected.log.gz" : "csail-robotlaser1.log.gz";
        const std::string path = opt.data_dir + "/" + file;
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
        wl.name = w + "_" + fmt(res * 100, 0) + "cm";
        wl.label = label;
        wl.resolution = res;
        wl.scans = scans;
        wl.timed_scans =
            opt.timed_scans == 0 ? scans.size() : std::min(opt.timed_scans, scans.size());
        std::cerr << wl.name << ": " << wl.scans.size() << " scans, " << wl.timed_scans
                  << " timed per repetition" << std::endl;
        results.push_back(runWorkload(wl, opt));
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "wavog_compare: " << e.what() << "\n";
    return 1;
  }
  if (results.empty()) {
    std::cerr << "wavog_compare: no workload ran\n";
    return 1;
  }

  const std::string text = report(results, opt);
  std::cout << text;
  std::ofstream md(opt.out_dir + "/results.md");
  md << text;
  std::ofstream csv(opt.out_dir + "/results.csv");
  csv << "workload,resolution_m,scans,timed_scans,structure,scans_per_s_cpu,scans_per_s_wall,"
         "rep_min_cpu_s,rep_max_cpu_s,"
         "warmup_s,own_bytes,rss_growth_bytes,observed_cells,work_per_scan\n";
  for (const WorkloadResult& r : results) {
    for (int k = 0; k < kSubjects; ++k) {
      const SubjectResult& s = r.subject[k];
      csv << r.name << "," << r.resolution << "," << r.scans << "," << r.timed_scans << ","
          << kSubjectNames[k] << "," << s.scans_per_s << "," << s.scans_per_s_wall << "," << s.min_s
          << "," << s.max_s << "," << s.warmup_s << "," << s.own_bytes << "," << s.rss_growth << ","
          << s.observed << "," << s.work_per_scan << "\n";
    }
  }
  if (!md || !csv) {
    std::cerr << "wavog_compare: cannot write results to " << opt.out_dir << "\n";
    return 1;
  }
  std::cerr << "wrote " << opt.out_dir << "/results.md, results.csv and the disagreement PNGs\n";
  return 0;
}
