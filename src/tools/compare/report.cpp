#include "compare/report.h"

#include <sys/utsname.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#ifndef WAVOG_SOURCE_DIR
#define WAVOG_SOURCE_DIR "."
#endif
#ifndef WAVOG_COMPARE_BUILD_TYPE
#define WAVOG_COMPARE_BUILD_TYPE "unknown"
#endif
#ifndef WAVOG_OCTOMAP_VERSION
#define WAVOG_OCTOMAP_VERSION "unknown"
#endif

namespace wavog_compare {
namespace {

namespace fs = std::filesystem;

std::string fmt(double v, int precision) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(precision) << v;
  return os.str();
}

/// A target's verdict, in bold.
const char* verdict(bool ok) { return ok ? "**met**" : "**not met**"; }

/// A workload and its resolution, as the target lines name them.
std::string where(const WorkloadResult& r) {
  return r.label + " " + fmt(r.resolution * 100, 0) + " cm";
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

/// Speed: scans/s by thread CPU time and the ratios between the structures.
void speedTable(const std::vector<WorkloadResult>& results, const Options& opt, std::ostream& os) {
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
}

/// Work per scan of the warm-up run.
void workTable(const std::vector<WorkloadResult>& results, std::ostream& os) {
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
}

/// Memory: bytes per observed cell, own account and resident-set growth.
void memoryTable(const std::vector<WorkloadResult>& results, std::ostream& os) {
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
}

/// Agreement over the cells all three observed.
void agreementTable(const std::vector<WorkloadResult>& results, std::ostream& os) {
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
}

/// The targets of issue 6, met or not.
void targets(const std::vector<WorkloadResult>& results, std::ostream& os) {
  os << "\n### Targets (issue 6; wavog-clamp unless stated)\n\n";
  const auto find = [&results](const std::string& name, double res) -> const WorkloadResult* {
    for (const WorkloadResult& r : results) {
      if (r.name.rfind(name, 0) == 0 && std::abs(r.resolution - res) < 1e-9) return &r;
    }
    return nullptr;
  };
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
}

/// Issue 43's bytes targets: bytes per observed cell not above those before the details were
/// stored as doubles. Measured on maps made with 80 m no-return clearing; without it the maps are
/// others, so a run without clearing has no bytes targets.
void bytesTargets(const std::vector<WorkloadResult>& results, std::ostream& os) {
  struct Before {
    const char* name;
    double resolution, clamp, forget;
  };
  const Before before[] = {{"fr079", 0.05, 2.92, 3.92},    {"fr079", 0.10, 4.15, 5.23},
                           {"csail", 0.05, 2.32, 2.32},    {"csail", 0.10, 3.71, 3.72},
                           {"lms291x4", 0.05, 0.18, 0.18}, {"lms291x4", 0.10, 0.33, 0.33}};
  for (const WorkloadResult& r : results) {
    for (const Before& b : before) {
      if (r.name.rfind(b.name, 0) != 0 || std::abs(r.resolution - b.resolution) > 1e-9) continue;
      const double c = perCell(r.subject[kWavogClamp].own_bytes, r.subject[kWavogClamp].observed);
      const double f = perCell(r.subject[kWavogForget].own_bytes, r.subject[kWavogForget].observed);
      os << "- bytes per observed cell not above " << fmt(b.clamp, 2) << " / " << fmt(b.forget, 2)
         << ", " << where(r) << ": " << fmt(c, 2) << " / " << fmt(f, 2) << ", "
         << verdict(c <= b.clamp + 0.005 && f <= b.forget + 0.005) << "\n";
    }
  }
}

/// The targets of issue 43 (dense leaf tiles classified by row runs), met or not: wavog-clamp
/// and wavog-forget over dense, indoors 0.75x with no-return clearing and 1.0x without.
void denseParityTargets(const std::vector<WorkloadResult>& results, const Options& opt,
                        std::ostream& os) {
  os << "\n### Targets (issue 43; wavog-clamp / wavog-forget)\n\n";
  const auto ratio = [](const WorkloadResult& r, int subject) {
    return r.subject[subject].scans_per_s / r.subject[kDense].scans_per_s;
  };
  const bool clearing = opt.no_return_clear > 0;
  const double indoor = clearing ? 0.75 : 1.0;
  for (const WorkloadResult& r : results) {
    if (r.name.rfind("lms291x4", 0) == 0) continue;
    const double c = ratio(r, kWavogClamp), f = ratio(r, kWavogForget);
    os << "- at least " << fmt(indoor, 2) << "x dense (" << (clearing ? "with" : "without")
       << " no-return clearing), " << where(r) << ": " << fmt(c, 2) << "x / " << fmt(f, 2) << "x, "
       << verdict(c >= indoor && f >= indoor) << "\n";
  }
  // 80 m at 5 cm: twice the ratios of one run when issue 43 was filed (3.69x clamp, 4.99x
  // forget), rounded: ratios of one run, comparable across machines as a guide.
  for (const WorkloadResult& r : results) {
    if (r.name.rfind("lms291x4", 0) != 0 || std::abs(r.resolution - 0.05) > 1e-9) continue;
    const double c = ratio(r, kWavogClamp), f = ratio(r, kWavogForget);
    os << "- at least 7.4x / 10x dense, " << where(r) << ": " << fmt(c, 2) << "x / " << fmt(f, 2)
       << "x, " << verdict(c >= 7.4 && f >= 10.0) << "\n";
  }
  if (clearing) bytesTargets(results, os);
  os << "\nThe instructions of each part of a scan, and how to measure them: docs/compare.md.\n";
}

/// Repetition times (thread CPU and wall clock) and the CPU share.
void repetitionTable(const std::vector<WorkloadResult>& results, const Options& opt,
                     std::ostream& os) {
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
}

/// pictures.json: each disagreement PNG with its extent in metres, and the colours' meanings, for
/// scripts/plot_compare.py.
nlohmann::ordered_json picturesJson(const std::vector<WorkloadResult>& results) {
  nlohmann::ordered_json j;
  j["legend"] = nlohmann::ordered_json::array();
  for (const LegendEntry& e : disagreementLegend()) {
    j["legend"].push_back({{"meaning", e.meaning}, {"rgb", {e.colour.r, e.colour.g, e.colour.b}}});
  }
  j["workloads"] = nlohmann::ordered_json::array();
  for (const WorkloadResult& r : results) {
    nlohmann::ordered_json pictures = nlohmann::ordered_json::array();
    for (const Picture& p : r.pictures) {
      const wavog::CellBox& c = p.cells;
      pictures.push_back({{"file", p.file},
                          {"other", p.other},
                          {"zoom", p.zoom},
                          {"extent_m",
                           {static_cast<double>(c.min_x) * r.resolution,
                            static_cast<double>(c.max_x) * r.resolution,
                            static_cast<double>(c.min_y) * r.resolution,
                            static_cast<double>(c.max_y) * r.resolution}}});
    }
    j["workloads"].push_back({{"name", r.name},
                              {"label", r.label},
                              {"resolution_m", r.resolution},
                              {"pictures", pictures}});
  }
  return j;
}

}  // namespace

std::string report(const std::vector<WorkloadResult>& results, const Options& opt) {
  std::ostringstream os;
  speedTable(results, opt, os);
  workTable(results, os);
  memoryTable(results, os);
  agreementTable(results, os);
  targets(results, os);
  denseParityTargets(results, opt, os);
  repetitionTable(results, opt, os);
  return os.str();
}

void writeResults(const std::vector<WorkloadResult>& results, const Options& opt,
                  const std::string& text) {
  std::ofstream md(fs::path(opt.out_dir) / "results.md");
  md << text;
  std::ofstream csv(fs::path(opt.out_dir) / "results.csv");
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
  if (!md || !csv) throw std::runtime_error("cannot write results to " + opt.out_dir);
  wavog_tools::writeJson((fs::path(opt.out_dir) / "pictures.json").string(), picturesJson(results));
}

}  // namespace wavog_compare
