// How much a dense leaf tile could save (issue 29): after a real log, how many tiles of T x T
// finest cells hold anything but one value (they would be stored as dense tiles, every cell a
// value), and so the fewest bytes per observed cell a map of dense float (or 16-bit) tiles could
// take, against what the map takes now (MapStats, tau = 0). Prints a table; no timing. Run by
// hand: ./build/bench/bench_tiles (the logs of ../shared/data or $WAVOG_DATA_DIR).
#include <cmath>
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/io/carmen_reader.h"

namespace {

struct Workload {
  const char* name;
  const char* file;
  std::size_t stride;  // as make compare thins the logs
};

void report(const char* name, const char* policy, double no_return_clear,
            const wavog::WaveletMap& map) {
  wavog::CellBox box;
  if (!map.bounds(0, &box)) return;
  const wavog::Raster r = map.exportScale(0, box, wavog::Aggregation::kMean);
  const std::int64_t w = r.box.max_x - r.box.min_x, h = r.box.max_y - r.box.min_y;
  const wavog::MapStats st = map.stats(true);
  std::printf("%s, %s, no-return beams clear %.0f m: %zu observed cells, now %.2f bytes/cell\n",
              name, policy, no_return_clear, st.observed_cells,
              static_cast<double>(st.bytes) / static_cast<double>(st.observed_cells));
  for (int t : {4, 8, 16}) {
    std::size_t mixed = 0, observed_in_mixed = 0;
    for (std::int64_t y0 = 0; y0 < h; y0 += t) {
      for (std::int64_t x0 = 0; x0 < w; x0 += t) {
        bool any = false, all = true, uniform = true;
        std::size_t seen = 0;
        const float first = r.log_odds[static_cast<std::size_t>(y0 * w + x0)];
        for (std::int64_t y = y0; y < std::min(h, y0 + t); ++y) {
          for (std::int64_t x = x0; x < std::min(w, x0 + t); ++x) {
            const auto i = static_cast<std::size_t>(y * w + x);
            const bool k = r.known[i] != 0;
            any = any || k;
            all = all && k;
            seen += k ? 1 : 0;
            uniform = uniform && std::fabs(r.log_odds[i] - first) <= 1e-6f;
          }
        }
        if (any && (!uniform || !all)) {
          ++mixed;
          observed_in_mixed += seen;
        }
      }
    }
    const double cells = static_cast<double>(mixed) * t * t;
    const double obs = static_cast<double>(st.observed_cells);
    std::printf("  %2d x %-2d tiles: %7zu not uniform, %4.1f %% of the observed cells in them; "
                "their cells alone: >= %.2f bytes/cell as float, %.2f as int16\n", t, t, mixed, 100.0 * static_cast<double>(observed_in_mixed) / obs,
                4.0 * cells / obs, 2.0 * cells / obs);
  }
}

}  // namespace

int main() {
  const std::string dir = wavog::findDataDir(WAVOG_SOURCE_DIR);
  if (dir.empty()) {
    std::fprintf(stderr, "bench_tiles: no data directory (../shared/data or WAVOG_DATA_DIR)\n");
    return 1;
  }
  for (const Workload wl : {Workload{"fr079", "fr079-corrected.log.gz", 12},
                            Workload{"csail", "csail-robotlaser1.log.gz", 14}}) {
    const auto log = wavog::readCarmenLog(dir + "/" + wl.file);
    for (double no_return_clear : {80.0, 0.0}) {
      for (wavog::PolicyType type : {wavog::PolicyType::kClamp, wavog::PolicyType::kForget}) {
        wavog::MapParams p = wavog::MapParams::defaultsFor(type);
        p.grid.resolution = 0.05;
        p.sensor.no_return_clear = no_return_clear;
        wavog::WaveletMap map(p);
        for (std::size_t i = 0; i < log.size(); i += wl.stride) {
          map.integrate(log[i].laser_pose, log[i].view());
        }
        report(wl.name, type == wavog::PolicyType::kClamp ? "clamp" : "forget", no_return_clear,
               map);
      }
    }
  }
  return 0;
}
