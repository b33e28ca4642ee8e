// Core benchmarks (make bench): scans/s, nodes visited per scan and bytes per observed cell for
// clamping, lazy forgetting and eager forgetting on fr079 and on synthetic 80 m LMS-291 scans,
// then the ratios of the issue's targets, computed from medians measured in this same run; and
// the speed-up of 2 threads over 1 (num_threads) at two block sizes (blocks per scan).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/io/carmen_reader.h"

namespace {

using wavog::MapParams;
using wavog::PolicyType;

struct Scan {
  wavog::Pose2 pose;
  std::vector<float> ranges;
  double angle_min, angle_increment, range_min, range_max;
  wavog::ScanView view() const {
    return {ranges.data(), ranges.size(), angle_min, angle_increment, range_min, range_max};
  }
};

std::vector<Scan> loadFr079() {
  const std::string dir = wavog::findDataDir(WAVOG_SOURCE_DIR);
  std::vector<Scan> out;
  if (dir.empty()) return out;
  for (const auto& c : wavog::readCarmenLog(dir + "/fr079-corrected.log.gz")) {
    const auto v = c.view();
    out.push_back({c.laser_pose, c.ranges, v.angle_min, v.angle_increment, v.range_min, v.range_max});
  }
  return out;
}

// A vehicle driving a gentle S curve at 5 m/s; one LMS-291 at 40 Hz (361 beams over 180 deg)
// seeing surfaces 60-80 m away that vary with bearing and time.
std::vector<Scan> synthetic80m(int count) {
  const double kPi = 3.14159265358979323846;
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Scan> out;
  for (int i = 0; i < count; ++i) {
    Scan s;
    const double t = i * 0.025;  // 40 Hz
    s.pose = {5.0 * t, 3.0 * std::sin(0.2 * t), 0.3 * std::cos(0.2 * t)};
    s.angle_min = -kPi / 2;
    s.angle_increment = kPi / 360;
    s.range_min = 0.5;
    s.range_max = 81.0;
    for (int j = 0; j < 361; ++j) {
      const double b = s.angle_min + j * s.angle_increment;
      double r = 70.0 + 8.0 * std::sin(3 * b + 0.05 * t) + 2.0 * std::sin(17 * b) + (u(rng) - 0.5) * 0.1;
      s.ranges.push_back(static_cast<float>(r));
    }
    out.push_back(std::move(s));
  }
  return out;
}

const std::vector<Scan>& workload(const std::string& name) {
  static std::map<std::string, std::vector<Scan>> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  // WAVOG_BENCH_SCANS caps the scans per workload (the ctest smoke run uses it).
  const char* cap_env = std::getenv("WAVOG_BENCH_SCANS");
  const std::size_t cap = cap_env ? static_cast<std::size_t>(std::atol(cap_env)) : 0;
  auto scans = name == "fr079" ? loadFr079() : synthetic80m(cap > 0 ? static_cast<int>(cap) : 1000);
  if (cap > 0 && scans.size() > cap) scans.resize(cap);
  return cache[name] = std::move(scans);
}

enum Variant {
  kClamp = 0,
  kForgetLazy = 1,
  kForgetEager = 2,
  kClampReflection = 3,  // with the reflection layers (MapParams::reflection)
  kForgetReflection = 4,
  kClampNdt = 5,  // with normal-distribution cells (MapParams::ndt)
  kForgetNdt = 6,
};
const char* kVariantNames[] = {"clamp",      "forget_lazy",     "forget_eager", "clamp+reflection",
                               "forget_lazy+reflection", "clamp+ndt", "forget_lazy+ndt"};

MapParams paramsFor(Variant v, double res, double tau) {
  const bool clamp = v == kClamp || v == kClampReflection || v == kClampNdt;
  MapParams p = MapParams::defaultsFor(clamp ? PolicyType::kClamp : PolicyType::kForget);
  p.grid.resolution = res;
  p.lazy_forgetting = v != kForgetEager;
  p.prune_threshold = tau;
  p.reflection = v == kClampReflection || v == kForgetReflection;
  p.ndt = v == kClampNdt || v == kForgetNdt;
  return p;
}

// Thread CPU time: on a shared machine it leaves out the time spent waiting for a core.
double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Figures {
  double scans_per_s = 0, visited_per_scan = 0, bytes_per_cell = 0;
};
std::map<std::string, std::vector<double>> g_rates;  // key -> scans/s per repetition
std::map<std::string, Figures> g_figures;

void BM_Integrate(benchmark::State& state, std::string wl, double res, Variant v) {
  const auto& scans = workload(wl);
  if (scans.empty()) {
    state.SkipWithError("data set not found (../shared/data or WAVOG_DATA_DIR)");
    return;
  }
  const std::string key = wl + "@" + std::to_string(static_cast<int>(std::lround(res * 100))) + "cm/" + kVariantNames[v];
  Figures f;
  for (auto _ : state) {
    wavog::WaveletMap map(paramsFor(v, res, 0.0));
    std::uint64_t visited = 0;
    const double t0 = threadCpuSeconds();
    for (const auto& s : scans) visited += map.integrate(s.pose, s.view()).nodes_visited;
    const double secs = threadCpuSeconds() - t0;
    state.SetIterationTime(secs);
    state.PauseTiming();
    const auto st = map.stats(true);
    f.scans_per_s = static_cast<double>(scans.size()) / secs;
    f.visited_per_scan = static_cast<double>(visited) / static_cast<double>(scans.size());
    f.bytes_per_cell = static_cast<double>(st.bytes) / static_cast<double>(std::max<std::uint64_t>(1, st.observed_cells));
    g_rates[key].push_back(f.scans_per_s);
    state.ResumeTiming();
  }
  g_figures[key] = f;
  state.counters["scans_per_s"] = f.scans_per_s;
  state.counters["visited_per_scan"] = f.visited_per_scan;
  state.counters["bytes_per_cell"] = f.bytes_per_cell;
}

// Region shards (MapParams::region, issue 36): a shard whose region the scans never reach (its
// blocks 1000 blocks away) against the map of every block, on the same scans: the cost a shard
// pays for a scan that misses its region, as a share of integrating it (target <= 5 %).
std::map<std::string, std::vector<double>> g_region_us;  // key -> us per scan per repetition

void BM_Region(benchmark::State& state, std::string wl, double res, Variant v, bool miss) {
  const auto& scans = workload(wl);
  if (scans.empty()) {
    state.SkipWithError("data set not found (../shared/data or WAVOG_DATA_DIR)");
    return;
  }
  MapParams p = paramsFor(v, res, 0.0);
  if (miss) {
    p.region.all = false;
    p.region.min_bx = p.region.min_by = 1000;
    p.region.max_bx = p.region.max_by = 1001;
  }
  const std::string key = wl + "@" + std::to_string(static_cast<int>(std::lround(res * 100))) +
                          "cm/" + kVariantNames[v] + (miss ? "/miss" : "/all");
  for (auto _ : state) {
    wavog::WaveletMap map(p);
    const double t0 = threadCpuSeconds();
    for (const auto& s : scans) benchmark::DoNotOptimize(map.integrate(s.pose, s.view()));
    const double secs = threadCpuSeconds() - t0;
    state.SetIterationTime(secs);
    g_region_us[key].push_back(1e6 * secs / static_cast<double>(scans.size()));
  }
}

// Parallel integration (num_threads): wall-clock time, since the work is on several threads.
// `levels`: block_levels, which sets the blocks per scan (the unit of work shared out).
std::map<std::string, std::vector<double>> g_wall;  // key -> scans/s per repetition
std::map<std::string, double> g_blocks_per_scan;

double clockSeconds(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
double wallSeconds() { return clockSeconds(CLOCK_MONOTONIC); }

std::string parallelKey(const std::string& wl, Variant v, int levels, int threads) {
  return wl + "@5cm/" + kVariantNames[v] + "/L" + std::to_string(levels) + "/threads:" +
         std::to_string(threads);
}

void BM_Parallel(benchmark::State& state, std::string wl, Variant v, int levels, int threads) {
  const auto& scans = workload(wl);
  if (scans.empty()) {
    state.SkipWithError("data set not found (../shared/data or WAVOG_DATA_DIR)");
    return;
  }
  const std::string key = parallelKey(wl, v, levels, threads);
  MapParams p = paramsFor(v, 0.05, 0.0);
  p.grid.block_levels = levels;
  p.num_threads = threads;
  double rate = 0, blocks = 0, cpu_us = 0;
  for (auto _ : state) {
    wavog::WaveletMap map(p);
    std::uint64_t touched = 0;
    map.integrate(scans[0].pose, scans[0].view());  // starts the workers outside the timing
    map.reset();
    const double t0 = wallSeconds(), c0 = clockSeconds(CLOCK_PROCESS_CPUTIME_ID);
    for (const auto& s : scans) touched += map.integrate(s.pose, s.view()).blocks_touched;
    const double secs = wallSeconds() - t0;
    // CPU time of every thread: the work, whatever the load (its growth is the cost of sharing).
    cpu_us = 1e6 * (clockSeconds(CLOCK_PROCESS_CPUTIME_ID) - c0) / static_cast<double>(scans.size());
    state.SetIterationTime(secs);
    rate = static_cast<double>(scans.size()) / secs;
    blocks = static_cast<double>(touched) / static_cast<double>(scans.size());
    g_wall[key].push_back(rate);
  }
  g_blocks_per_scan[key] = blocks;
  state.counters["scans_per_s"] = rate;
  state.counters["blocks_per_scan"] = blocks;
  state.counters["cpu_us_per_scan"] = cpu_us;
}

// The parallel cases: (workload, variant, block_levels).
struct ParallelCase {
  const char* wl;
  Variant v;
  int levels;
};
constexpr ParallelCase kParallelCases[] = {{"synthetic80m", kForgetLazy, 9},
                                           {"synthetic80m", kForgetLazy, 7},
                                           {"fr079", kClamp, 9},
                                           {"fr079", kClamp, 7}};

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void printSummary() {
  std::printf("\n== Summary (scans/s over the median thread CPU time of the repetitions) ==\n");
  std::printf("%-32s %12s %14s %14s\n", "workload/variant", "scans/s", "visited/scan", "bytes/cell");
  for (const auto& kv : g_figures) {
    std::printf("%-32s %12.0f %14.0f %14.3f\n", kv.first.c_str(), median(g_rates[kv.first]),
                kv.second.visited_per_scan, kv.second.bytes_per_cell);
  }
  auto m = [](const std::string& k) { return median(g_rates[k]); };
  // A ratio of two variants, only when the run measured both (a --benchmark_filter may leave one
  // out).
  auto both = [](const std::string& a, const std::string& b) {
    return g_rates.count(a) > 0 && g_rates.count(b) > 0;
  };
  std::printf("\n== Targets ==\n");
  for (const char* wl : {"fr079", "synthetic80m"}) {
    for (const char* res : {"5cm", "10cm"}) {
      const std::string base = std::string(wl) + "@" + res + "/";
      if (both(base + "clamp", base + "forget_lazy")) {
        std::printf("%-20s forget_lazy cost / clamp cost = %.2f (target <= 1.1)\n",
                    (std::string(wl) + "@" + res).c_str(),
                    m(base + "clamp") / m(base + "forget_lazy"));
      }
      if (both(base + "forget_lazy", base + "forget_eager")) {
        std::printf("%-20s lazy / eager speed           = %.2f (target >= 3 on 80 m)\n",
                    (std::string(wl) + "@" + res).c_str(),
                    m(base + "forget_lazy") / m(base + "forget_eager"));
      }
      for (const char* payload : {"reflection", "ndt"}) {
        const double target = std::string(payload) == "ndt" ? 1.5 : 1.3;
        for (const char* v : {"clamp", "forget_lazy"}) {
          const std::string with = base + v + "+" + payload;
          if (!both(base + v, with)) continue;
          std::printf("%-20s %-11s %-10s cost / occupancy alone = %.2f (target <= %.1f), "
                      "bytes/cell %.3f -> %.3f\n",
                      (std::string(wl) + "@" + res).c_str(), v, payload, m(base + v) / m(with),
                      target, g_figures[base + v].bytes_per_cell, g_figures[with].bytes_per_cell);
        }
      }
    }
  }
  if (g_rates.count("synthetic80m@5cm/forget_lazy")) {
    std::printf("synthetic80m@5cm forget_lazy: %.0f scans/s (target >= 1000)\n", m("synthetic80m@5cm/forget_lazy"));
  }
  bool any_parallel = false;
  for (const auto& c : kParallelCases) {
    const std::string one = parallelKey(c.wl, c.v, c.levels, 1), two = parallelKey(c.wl, c.v, c.levels, 2);
    if (!g_wall.count(one) || !g_wall.count(two)) continue;
    if (!any_parallel) {
      std::printf("\n== Parallel integration: 2 threads over 1 (wall-clock medians, this run) ==\n");
      any_parallel = true;
    }
    // Issue 29: indoors (a scan's blocks split below their roots) >= 1.6, at 80 m >= 1.7, with
    // the default 9 levels.
    const bool indoor = std::string(c.wl) == "fr079";
    std::string target = "-";
    if (c.levels == 9) target = indoor ? ">= 1.6" : ">= 1.7";
    std::printf("%-36s %8.0f -> %8.0f scans/s, speed-up %.2f (%.1f blocks/scan; target %s)\n",
                (std::string(c.wl) + "@5cm/" + kVariantNames[c.v] + "/L" + std::to_string(c.levels)).c_str(),
                median(g_wall[one]), median(g_wall[two]), median(g_wall[two]) / median(g_wall[one]),
                g_blocks_per_scan[one], target.c_str());
  }
  bool any_region = false;
  for (const auto& kv : g_region_us) {
    const std::string k = kv.first;
    if (k.size() < 5 || k.substr(k.size() - 5) != "/miss") continue;
    const std::string all = k.substr(0, k.size() - 5) + "/all";
    if (!g_region_us.count(all)) continue;
    if (!any_region) {
      std::printf("\n== Region shards: a scan that misses the shard's region ==\n");
      any_region = true;
    }
    const double miss_us = median(kv.second), all_us = median(g_region_us[all]);
    std::printf("%-32s %8.2f us per missed scan, %8.1f us integrated: %.1f %% (target <= 5 %%)\n",
                all.substr(0, all.size() - 4).c_str(), miss_us, all_us, 100.0 * miss_us / all_us);
  }
  // Memory and pruning error on fr079 at 5 cm with forgetting, tau = 0, 0.01, 0.05.
  if (!g_rates.count("fr079@5cm/forget_lazy")) return;  // only with the fr079 5 cm runs
  const auto& scans = workload("fr079");
  std::printf("\n== fr079 @ 5 cm, forgetting: memory and pruning error ==\n");
  wavog::WaveletMap exact(paramsFor(kForgetLazy, 0.05, 0.0));
  for (const auto& s : scans) exact.integrate(s.pose, s.view());
  wavog::CellBox box;
  exact.bounds(0, &box);
  const auto ref = exact.exportScale(0, box, wavog::Aggregation::kMean);
  for (double tau : {0.0, 0.01, 0.05}) {
    wavog::WaveletMap map(paramsFor(kForgetLazy, 0.05, tau));
    for (const auto& s : scans) map.integrate(s.pose, s.view());
    const auto st = map.stats(true);
    const auto r = map.exportScale(0, box, wavog::Aggregation::kMean);
    double max_err = 0;
    for (std::size_t i = 0; i < r.log_odds.size(); ++i) {
      max_err = std::max(max_err, static_cast<double>(std::fabs(r.log_odds[i] - ref.log_odds[i])));
    }
    std::printf("tau %.2f: %zu nodes, %zu bytes (%zu reserved), %llu observed cells, %.3f "
                "bytes/cell (%.3f reserved; target <= 1 at tau 0), max |error| vs tau 0: %.4f "
                "log-odds\n",
                tau, st.nodes, st.bytes, st.bytes_reserved,
                static_cast<unsigned long long>(st.observed_cells),
                static_cast<double>(st.bytes) / static_cast<double>(st.observed_cells),
                static_cast<double>(st.bytes_reserved) / static_cast<double>(st.observed_cells),
                max_err);
  }
}

}  // namespace

int main(int argc, char** argv) {
  for (const char* wl : {"fr079", "synthetic80m"}) {
    for (double res : {0.05, 0.10}) {
      for (Variant v : {kClamp, kForgetLazy, kForgetEager, kClampReflection, kForgetReflection,
                        kClampNdt, kForgetNdt}) {
        if (res != 0.05 && v != kClamp && v != kForgetLazy && v != kForgetEager) continue;
        const std::string name = std::string("integrate/") + wl + "/" +
                                 std::to_string(static_cast<int>(std::lround(res * 100))) + "cm/" + kVariantNames[v];
        benchmark::RegisterBenchmark(name.c_str(), BM_Integrate, std::string(wl), res, v)
            ->UseManualTime()
            ->Unit(benchmark::kMillisecond)
            ->Iterations(1)
            ->Repetitions(5)
            ->ReportAggregatesOnly(true);
      }
    }
  }
  for (const char* wl : {"fr079", "synthetic80m"}) {
    for (bool miss : {false, true}) {
      const std::string name = std::string("region/") + wl + "/5cm/forget_lazy/" +
                               (miss ? "miss" : "all");
      benchmark::RegisterBenchmark(name.c_str(), BM_Region, std::string(wl), 0.05, kForgetLazy, miss)
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond)
          ->Iterations(1)
          ->Repetitions(5)
          ->ReportAggregatesOnly(true);
    }
  }
  // Interleaved with the others by --benchmark_enable_random_interleaving (make bench), so the
  // 1- and 2-thread figures of one case see the same load.
  for (const auto& c : kParallelCases) {
    for (int threads : {1, 2}) {
      const std::string name = std::string("parallel/") + parallelKey(c.wl, c.v, c.levels, threads);
      benchmark::RegisterBenchmark(name.c_str(), BM_Parallel, std::string(c.wl), c.v, c.levels, threads)
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond)
          ->Iterations(1)
          ->Repetitions(5)
          ->ReportAggregatesOnly(true);
    }
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  printSummary();
  return 0;
}
