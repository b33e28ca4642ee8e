#include "compare/measure.h"

#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <memory>

#include "compare/subjects.h"
#include "wavog_mapping/core/params.h"
#include "wavog_mapping/io/image_io.h"

namespace wavog_compare {
namespace {

using Clock = std::chrono::steady_clock;

std::size_t residentBytes() {
  std::ifstream statm("/proc/self/statm");
  std::size_t size = 0, resident = 0;
  statm >> size >> resident;
  return resident * static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
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

/// Makes fresh structures of each kind for one workload, all with the same resolution and
/// no-return clearing (wavog clamp and dense with the same log-odds and clamps).
class SubjectFactory {
 public:
  SubjectFactory(const Workload& wl, const Options& opt)
      : resolution_(wl.resolution), no_return_clear_(opt.no_return_clear) {
    clamp_ = wavog::MapParams::defaultsFor(wavog::PolicyType::kClamp);
    clamp_.grid.resolution = wl.resolution;
    clamp_.sensor.no_return_clear = opt.no_return_clear;
    forget_ = wavog::MapParams::defaultsFor(wavog::PolicyType::kForget);
    forget_.grid.resolution = wl.resolution;
    forget_.sensor.no_return_clear = opt.no_return_clear;
    dense_.resolution = wl.resolution;
    dense_.hit_log_odds = clamp_.sensor.odd_occ;
    dense_.miss_log_odds = clamp_.sensor.odd_emp;
    dense_.clamp_min_log_odds = clamp_.policy.clamp_min;
    dense_.clamp_max_log_odds = clamp_.policy.clamp_max;
    dense_.no_return_clear_m = opt.no_return_clear;
  }

  std::unique_ptr<Subject> make(int k) const {
    switch (k) {
      case kWavogClamp:
        return std::make_unique<WavogSubject>(clamp_);
      case kWavogForget:
        return std::make_unique<WavogSubject>(forget_);
      case kOctoMap:
        return std::make_unique<OctoMapSubject>(resolution_, no_return_clear_);
      default:
        return std::make_unique<DenseSubject>(dense_, dense_presize_);
    }
  }

  /// The warm-up grows the dense grid as scans arrive; the timed runs get it pre-sized to that
  /// extent (allocation untimed, like the other structures' construction), its best case.
  void presizeDense(const wavog::CellBox& extent) { dense_presize_ = extent; }

 private:
  double resolution_;
  double no_return_clear_;
  wavog::MapParams clamp_;
  wavog::MapParams forget_;
  wavog::baseline::DenseGridParams dense_;
  wavog::CellBox dense_presize_;
};

using Subjects = std::array<std::unique_ptr<Subject>, kSubjects>;

/// Warm-up: the whole workload into a fresh structure of each kind. Its map is the one compared,
/// and the growth of the resident set during it is the RSS memory figure (freed heap returned
/// first).
Subjects warmUp(const SubjectFactory& factory, const Workload& wl, WorkloadResult* res) {
  Subjects full;
  for (int k = 0; k < kSubjects; ++k) {
    SubjectResult& r = res->subject[k];
    malloc_trim(0);
    const std::size_t rss0 = residentBytes();
    full[k] = factory.make(k);
    const auto t0 = Clock::now();
    for (const Scan& s : wl.scans) full[k]->integrate(s);
    const auto t1 = Clock::now();
    r.warmup_s = seconds(t0, t1);
    r.rss_growth = residentBytes() - std::min(rss0, residentBytes());
    r.own_bytes = full[k]->ownBytes();
    r.observed = full[k]->observedCells();
    r.work_per_scan = static_cast<double>(full[k]->work()) / static_cast<double>(wl.scans.size());
  }
  return full;
}

/// Timed repetitions, each into a fresh structure (construction and destruction not timed). The
/// structures take turns within each repetition, so a burst of load from other processes on a
/// shared machine lands on all of them rather than on one.
void timeRepetitions(const SubjectFactory& factory, const Workload& wl, int reps,
                     WorkloadResult* res) {
  for (int rep = 0; rep < reps; ++rep) {
    for (int k = 0; k < kSubjects; ++k) {
      std::unique_ptr<Subject> m = factory.make(k);
      const auto a = Clock::now();
      const double ca = threadCpuSeconds();
      for (std::size_t i = 0; i < wl.timed_scans; ++i) m->integrate(wl.scans[i]);
      const double cb = threadCpuSeconds();
      const auto b = Clock::now();
      res->subject[k].rep_seconds.push_back(cb - ca);
      res->subject[k].rep_wall.push_back(seconds(a, b));
    }
  }
  for (int k = 0; k < kSubjects; ++k) {
    SubjectResult& r = res->subject[k];
    r.scans_per_s = static_cast<double>(wl.timed_scans) / median(r.rep_seconds);
    r.scans_per_s_wall = static_cast<double>(wl.timed_scans) / median(r.rep_wall);
    r.min_s = *std::min_element(r.rep_seconds.begin(), r.rep_seconds.end());
    r.max_s = *std::max_element(r.rep_seconds.begin(), r.rep_seconds.end());
    std::cerr << "  " << std::setw(12) << kSubjectNames[k] << ": " << std::fixed
              << std::setprecision(1) << r.scans_per_s << " scans/s (warm-up "
              << std::setprecision(2) << r.warmup_s << " s), " << r.own_bytes << " B own, "
              << r.rss_growth << " B RSS, " << r.observed << " observed cells" << std::endl;
  }
}

/// Agreement over the cells all three kinds observed, inside the dense grid's observed box, and
/// the pictures of wavog-clamp's disagreements with each other map (full and zoomed).
void compareMaps(const Subjects& full, const Workload& wl, const Options& opt,
                 WorkloadResult* res) {
  const wavog::CellBox box = static_cast<const DenseSubject&>(*full[kDense]).observedBox();
  if (box.empty()) return;
  std::vector<std::uint8_t> cls[kSubjects];
  for (int k = 0; k < kSubjects; ++k) cls[k] = full[k]->classify(box);
  res->clamp_octomap = agreement(cls[kWavogClamp], cls[kOctoMap], cls[kDense], cls[kDense]);
  res->clamp_dense = agreement(cls[kWavogClamp], cls[kDense], cls[kOctoMap], cls[kOctoMap]);
  res->octomap_dense = agreement(cls[kOctoMap], cls[kDense], cls[kWavogClamp], cls[kWavogClamp]);
  res->forget_octomap = agreement(cls[kWavogForget], cls[kOctoMap], cls[kDense], cls[kDense]);
  res->forget_dense = agreement(cls[kWavogForget], cls[kDense], cls[kOctoMap], cls[kOctoMap]);

  std::vector<std::uint8_t> all3(cls[kDense].size(), 0);
  for (std::size_t i = 0; i < all3.size(); ++i) {
    all3[i] =
        (cls[kWavogClamp][i] != kUnobs && cls[kOctoMap][i] != kUnobs && cls[kDense][i] != kUnobs)
            ? 1
            : 0;
  }
  const std::string stem = "disagree_" + wl.name;
  for (const int other : {kOctoMap, kDense}) {
    const std::string suffix = other == kOctoMap ? "octomap" : "dense";
    const wavog::CellBox zoom =
        densestDisagreement(cls[kWavogClamp], cls[other], all3, box, opt.crop_cells);
    for (const bool zoomed : {false, true}) {
      Picture pic{stem + "_vs_" + suffix + (zoomed ? "_zoom.png" : ".png"), kSubjectNames[other],
                  zoomed, zoomed ? zoom : box};
      wavog::writePng(
          (std::filesystem::path(opt.out_dir) / pic.file).string(),
          disagreementImage(cls[kWavogClamp], cls[other], all3, box, pic.cells, zoomed ? 3 : 1));
      res->pictures.push_back(pic);
    }
  }
}

}  // namespace

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::vector<LegendEntry> disagreementLegend() {
  return {{"both free", kColFree},
          {"both occupied", kColOcc},
          {"wavog occupied, other free", kColWavogOcc},
          {"wavog free, other occupied", kColWavogFree},
          {"one side at p = 0.5", kColHalf},
          {"observed by some, not all three", kColPartly},
          {"observed by none", kColUnobserved}};
}

WorkloadResult runWorkload(const Workload& wl, const Options& opt) {
  WorkloadResult res;
  res.label = wl.label;
  res.name = wl.name;
  res.resolution = wl.resolution;
  res.scans = wl.scans.size();
  res.timed_scans = wl.timed_scans;
  res.reps = opt.reps;
  SubjectFactory factory(wl, opt);
  const Subjects full = warmUp(factory, wl, &res);
  factory.presizeDense(static_cast<const DenseSubject&>(*full[kDense]).extent());
  timeRepetitions(factory, wl, opt.reps, &res);
  compareMaps(full, wl, opt, &res);
  return res;
}

}  // namespace wavog_compare
