// What wavog_compare measures on one workload: every structure's speed (thread CPU and wall time
// of timed repetitions after a warm-up), memory (own account, resident-set growth), observed cells
// and work per scan, their agreement over the commonly observed cells, and the disagreement PNGs.
// Private to wavog_compare; single-threaded.
#ifndef WAVOG_MAPPING_TOOLS_COMPARE_MEASURE_H_
#define WAVOG_MAPPING_TOOLS_COMPARE_MEASURE_H_

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "compare/options.h"
#include "compare/workloads.h"
#include "wavog_mapping/io/image_io.h"

namespace wavog_compare {

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

/// One disagreement PNG of wavog-clamp against another structure: 1 pixel per cell (full) or 3
/// (zoom), north up, covering `cells`.
struct Picture {
  std::string file;   ///< file name in the output folder
  std::string other;  ///< "OctoMap" or "dense"
  bool zoom = false;  ///< the window with the most disagreements
  wavog::CellBox cells;
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
  std::vector<Picture> pictures;  ///< the disagreement PNGs written
};

/// Runs every structure on one workload; writes the disagreement PNGs to opt.out_dir.
WorkloadResult runWorkload(const Workload& wl, const Options& opt);

/// What each colour of the disagreement pictures means, in drawing order.
struct LegendEntry {
  const char* meaning;
  wavog::Rgb colour;
};
std::vector<LegendEntry> disagreementLegend();

/// The median of `v` (not empty).
double median(std::vector<double> v);

}  // namespace wavog_compare

#endif  // WAVOG_MAPPING_TOOLS_COMPARE_MEASURE_H_
