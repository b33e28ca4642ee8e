// What the libFuzzer harnesses share: a per-process scratch file (the loaders read files), an
// oracle check that stops the run, and hostile numbers decoded from the fuzzer's bytes.
// Public core API only (include/wavog_mapping/...), so that the core's internals may move.
#ifndef WAVOG_MAPPING_TEST_FUZZ_FUZZ_SUPPORT_H_
#define WAVOG_MAPPING_TEST_FUZZ_FUZZ_SUPPORT_H_

#include <fuzzer/FuzzedDataProvider.h>
#include <unistd.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "wavog_mapping/core/limits.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog_fuzz {

/// A file of this process under /dev/shm (else $TMPDIR or /tmp): `name` distinguishes the uses.
inline std::string scratchPath(const std::string& name) {
  std::string dir = "/dev/shm";
  if (::access(dir.c_str(), W_OK) != 0) {
    const char* tmp = std::getenv("TMPDIR");
    dir = tmp != nullptr && tmp[0] != '\0' ? tmp : "/tmp";
  }
  return dir + "/wavog_fuzz_" + std::to_string(::getpid()) + "_" + name;
}

inline void writeFile(const std::string& path, const std::uint8_t* data, std::size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out) {
    std::fprintf(stderr, "fuzz harness: cannot write scratch file %s\n", path.c_str());
    std::abort();
  }
}

inline std::vector<char> readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  std::vector<char> out(in ? static_cast<std::size_t>(in.tellg()) : 0);
  in.seekg(0);
  in.read(out.data(), static_cast<std::streamsize>(out.size()));
  return out;
}

/// An oracle violation: prints and aborts, so libFuzzer records the input as a crash.
#define WAVOG_FUZZ_CHECK(cond, ...)                                                     \
  do {                                                                                  \
    if (!(cond)) {                                                                      \
      std::fprintf(stderr, "oracle failed: %s (%s:%d)\n  ", #cond, __FILE__, __LINE__); \
      std::fprintf(stderr, __VA_ARGS__);                                                \
      std::fprintf(stderr, "\n");                                                       \
      std::abort();                                                                     \
    }                                                                                   \
  } while (0)

/// Cells a harness reads out of one window at most (2^12, 64 x 64: larger windows mostly cost
/// instrumented fill loops; at 2^18 a 1 cm map with 4096-cell blocks took 2 s per input, reading
/// out six scales three times). A harness speed choice, not a core limit.
constexpr std::int64_t kReadOutCells = std::int64_t{1} << 12;

/// The window a harness reads out of `bounds` (which the core accepts, readoutFits): the bounds,
/// or their lower corner when they hold more than kReadOutCells cells.
inline wavog::CellBox readOutWindow(const wavog::CellBox& bounds) {
  wavog::CellBox w = bounds;
  if (static_cast<double>(w.width()) * static_cast<double>(w.height()) >
      static_cast<double>(kReadOutCells)) {
    w.max_x = w.min_x + std::min<std::int64_t>(w.width(), 64);
    w.max_y = w.min_y + std::min<std::int64_t>(w.height(), kReadOutCells / (w.max_x - w.min_x));
  }
  return w;
}

/// A read-out the core must refuse (more than kMaxReadoutCells cells): checks that exportScale
/// throws ReadoutTooLarge.
inline void expectReadOutRefused(const wavog::WaveletMap& map, int scale,
                                 const wavog::CellBox& window) {
  bool refused = false;
  try {
    (void)map.exportScale(scale, window, wavog::Aggregation::kMean);
  } catch (const wavog::ReadoutTooLarge&) {
    refused = true;
  }
  WAVOG_FUZZ_CHECK(refused, "scale %d: a window of %llu cells was read out", scale,
                   static_cast<unsigned long long>(wavog::readoutCells(window)));
}

/// Two rasters with the same window, knowledge and bit-identical values.
inline bool sameBits(const wavog::Raster& a, const wavog::Raster& b) {
  return a.scale == b.scale && a.box.min_x == b.box.min_x && a.box.min_y == b.box.min_y &&
         a.box.max_x == b.box.max_x && a.box.max_y == b.box.max_y && a.known == b.known &&
         a.log_odds.size() == b.log_odds.size() &&
         std::memcmp(a.log_odds.data(), b.log_odds.data(), a.log_odds.size() * sizeof(float)) == 0;
}

/// Cells of a scale-0 window whose point queries (value, reflection, ndtCell) a harness compares
/// with the window's read-out: at most this many, from its lower corner (a speed choice).
constexpr std::int64_t kPointQueries = 1024;

/// The lower-corner window of at most kPointQueries cells of a scale-0 window `box`.
inline wavog::CellBox pointQueryWindow(const wavog::CellBox& box) {
  wavog::CellBox q = box;
  q.max_x = q.min_x + std::min<std::int64_t>(q.width(), 32);
  q.max_y = q.min_y + std::min<std::int64_t>(q.height(), kPointQueries / (q.max_x - q.min_x));
  return q;
}

/// value() and isObserved() of each cell of the point-query window of the scale-0 window `box`
/// agree with its scale-0 read-out (mean): observed exactly where the read-out knows the cell,
/// reading its value (both from the same Haar averages, up to round-off), else the prior (issue
/// 28: a loaded file's cell read 0 by value() and -1.66 by the read-out).
inline void checkPointQueries(const wavog::WaveletMap& map, const wavog::CellBox& box) {
  const wavog::CellBox q = pointQueryWindow(box);
  const wavog::Raster r = map.exportScale(0, q, wavog::Aggregation::kMean);
  for (std::int64_t y = q.min_y, i = 0; y < q.max_y; ++y) {
    for (std::int64_t x = q.min_x; x < q.max_x; ++x, ++i) {
      const auto at = static_cast<std::size_t>(i);
      const bool known = r.known[at] != 0;
      const float a = map.value({x, y}), b = r.log_odds[at];
      WAVOG_FUZZ_CHECK(map.isObserved({x, y}) == known && std::isfinite(a) &&
                           std::fabs(a - b) <= 1e-6f * std::max(1.0f, std::fabs(b)),
                       "value(%lld, %lld) = %.9g observed %d, read-out %.9g known %d",
                       static_cast<long long>(x), static_cast<long long>(y),
                       static_cast<double>(a), map.isObserved({x, y}) ? 1 : 0,
                       static_cast<double>(b), known ? 1 : 0);
    }
  }
}

/// Every scale over the map's bounds, both aggregations (a window the core must refuse is checked
/// to be refused); each raster's size and its occupancy grid checked. Returns the rasters.
inline std::vector<wavog::Raster> readOutEveryScale(const wavog::WaveletMap& map) {
  std::vector<wavog::Raster> out;
  for (int s = 0; s <= map.params().grid.block_levels; ++s) {
    wavog::CellBox box;
    if (!map.bounds(s, &box)) break;
    if (!wavog::readoutFits(box)) {
      expectReadOutRefused(map, s, box);
      continue;
    }
    box = readOutWindow(box);
    if (s == 0) checkPointQueries(map, box);
    for (wavog::Aggregation agg : {wavog::Aggregation::kMean, wavog::Aggregation::kMax}) {
      wavog::Raster r = map.exportScale(s, box, agg);
      const auto cells =
          static_cast<std::size_t>(box.width()) * static_cast<std::size_t>(box.height());
      WAVOG_FUZZ_CHECK(r.log_odds.size() == cells && r.known.size() == cells,
                       "scale %d: raster of %zu cells for a %lld x %lld window", s,
                       r.log_odds.size(), static_cast<long long>(box.width()),
                       static_cast<long long>(box.height()));
      const auto grid = wavog::toOccupancyGrid(r);
      for (std::size_t i = 0; i < grid.size(); ++i) {
        // Every value a map holds is finite (issue 28: a loaded map turned NaN after a scan).
        WAVOG_FUZZ_CHECK(std::isfinite(r.log_odds[i]), "scale %d: log-odds %g at %zu", s,
                         static_cast<double>(r.log_odds[i]), i);
        WAVOG_FUZZ_CHECK(grid[i] >= -1 && grid[i] <= 100, "occupancy %d", grid[i]);
        WAVOG_FUZZ_CHECK((grid[i] == -1) == (r.known[i] == 0) || std::isnan(r.log_odds[i]),
                         "known flag and occupancy disagree at %zu", i);
      }
      out.push_back(std::move(r));
    }
    if (map.params().reflection) {
      const wavog::ReflectionRaster r = map.exportReflection(s, box);
      const auto grid = wavog::toOccupancyGrid(r);
      WAVOG_FUZZ_CHECK(grid.size() == r.p.size(), "reflection: %zu values for %zu cells",
                       grid.size(), r.p.size());
      for (std::size_t i = 0; i < grid.size(); ++i) {
        WAVOG_FUZZ_CHECK(std::isnan(r.p[i]) || (r.p[i] >= 0.0f && r.p[i] <= 1.0f),
                         "reflection p %g at %zu", static_cast<double>(r.p[i]), i);
        WAVOG_FUZZ_CHECK((grid[i] == -1) == std::isnan(r.p[i]), "reflection grid %d", grid[i]);
      }
    }
    if (map.params().ndt) {
      // Every Gaussian in the window, with a positive weight, its mean in its cell and a
      // covariance with a non-negative diagonal.
      const wavog::NdtLayer layer = map.exportNdt(s, box);
      for (const wavog::NdtCell& c : layer.cells) {
        WAVOG_FUZZ_CHECK(c.ix >= box.min_x && c.ix < box.max_x && c.iy >= box.min_y &&
                             c.iy < box.max_y,
                         "NDT cell outside the window at scale %d", s);
        WAVOG_FUZZ_CHECK(c.weight > 0.0 && std::isfinite(c.mean_x) && std::isfinite(c.mean_y) &&
                             c.cov_xx >= 0.0 && c.cov_yy >= 0.0 && std::isfinite(c.cov_xy),
                         "NDT cell weight %g cov %g %g", c.weight, c.cov_xx, c.cov_yy);
        const double lo = static_cast<double>(c.ix) * layer.cell_size;
        WAVOG_FUZZ_CHECK(c.mean_x >= lo - 1e-6 * layer.cell_size &&
                             c.mean_x <= lo + layer.cell_size * (1.0 + 1e-6),
                         "NDT mean %g outside its cell [%g, %g)", c.mean_x, lo,
                         lo + layer.cell_size);
      }
    }
  }
  return out;
}

/// The payload read-outs of every scale over the map's bounds (the reflection probabilities and
/// the Gaussians, flattened to floats / doubles), in a fixed order, for bit comparisons between
/// two maps; at scale 0 each agrees with its point query (reflection(), ndtCell()).
struct Payloads {
  std::vector<float> reflection;
  std::vector<double> ndt;
  bool operator==(const Payloads& o) const { return sameBits(reflection, o.reflection) && sameBits(ndt, o.ndt); }
  template <typename T>
  static bool sameBits(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() &&
           (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
  }
};

inline Payloads readPayloads(const wavog::WaveletMap& map) {
  Payloads out;
  const bool refl = map.params().reflection, ndt = map.params().ndt;
  for (int s = 0; s <= map.params().grid.block_levels; ++s) {
    wavog::CellBox box;
    if (!map.bounds(s, &box) || !wavog::readoutFits(box)) break;
    box = readOutWindow(box);
    const wavog::CellBox q = pointQueryWindow(box);  // for the point queries (scale 0)
    if (refl) {
      const wavog::ReflectionRaster r = map.exportReflection(s, box);
      out.reflection.insert(out.reflection.end(), r.p.begin(), r.p.end());
      if (s == 0) {
        const wavog::ReflectionRaster rq = map.exportReflection(0, q);
        for (std::int64_t y = q.min_y, i = 0; y < q.max_y; ++y) {
          for (std::int64_t x = q.min_x; x < q.max_x; ++x, ++i) {
            const float a = map.reflection({x, y}), b = rq.p[static_cast<std::size_t>(i)];
            // The point query and the raster compute the ratio by different float paths (the
            // raster from Haar averages): equal up to round-off.
            WAVOG_FUZZ_CHECK((std::isnan(a) && std::isnan(b)) || std::fabs(a - b) <= 1e-5f,
                             "reflection(%lld, %lld) = %.9g, read-out %.9g", static_cast<long long>(x),
                             static_cast<long long>(y), static_cast<double>(a),
                             static_cast<double>(b));
          }
        }
      }
    }
    if (ndt) {
      const wavog::NdtLayer layer = map.exportNdt(s, box);
      for (const wavog::NdtCell& c : layer.cells) {
        for (double v : {static_cast<double>(c.ix), static_cast<double>(c.iy), c.weight, c.mean_x,
                         c.mean_y, c.cov_xx, c.cov_xy, c.cov_yy,
                         static_cast<double>(c.log_odds)}) {
          WAVOG_FUZZ_CHECK(std::isfinite(v), "NDT read-out %g at scale %d", v, s);
          out.ndt.push_back(v);
        }
      }
      if (s == 0) {
        const wavog::NdtLayer lq = map.exportNdt(0, q);
        std::size_t held = 0;
        for (std::int64_t y = q.min_y; y < q.max_y; ++y) {
          for (std::int64_t x = q.min_x; x < q.max_x; ++x) {
            wavog::NdtCell c;
            if (!map.ndtCell({x, y}, &c)) continue;
            WAVOG_FUZZ_CHECK(held < lq.cells.size() && lq.cells[held].ix == x &&
                                 lq.cells[held].iy == y && lq.cells[held].weight == c.weight &&
                                 lq.cells[held].mean_x == c.mean_x &&
                                 lq.cells[held].mean_y == c.mean_y &&
                                 lq.cells[held].cov_xy == c.cov_xy,
                             "ndtCell(%lld, %lld) disagrees with the read-out",
                             static_cast<long long>(x), static_cast<long long>(y));
            ++held;
          }
        }
        WAVOG_FUZZ_CHECK(held == lq.cells.size(), "%zu Gaussians by point, %zu read out", held,
                         lq.cells.size());
      }
    }
  }
  return out;
}

/// A double a broken driver or an attacker might send: one of the hostile constants (NaN, +-inf,
/// -0, denormals, 1e300, FLT_MAX, 2^31, 2^63, ...), any bit pattern, or a value in [lo, hi].
inline double hostileDouble(FuzzedDataProvider* in, double lo, double hi) {
  static const double kHostile[] = {0.0,
                                    -0.0,
                                    1.0,
                                    -1.0,
                                    std::numeric_limits<double>::quiet_NaN(),
                                    std::numeric_limits<double>::infinity(),
                                    -std::numeric_limits<double>::infinity(),
                                    std::numeric_limits<double>::denorm_min(),
                                    -std::numeric_limits<double>::denorm_min(),
                                    std::numeric_limits<float>::denorm_min(),
                                    DBL_MIN,
                                    1e-300,
                                    1e300,
                                    -1e300,
                                    DBL_MAX,
                                    -DBL_MAX,
                                    FLT_MAX,
                                    -FLT_MAX,
                                    1e7,
                                    -1e7,
                                    1e19,
                                    -1e19,
                                    5e10,
                                    2147483648.0,
                                    4294967296.0,
                                    9.3e18,
                                    1e30,
                                    3.14159265358979323846,
                                    6.283185307179586,
                                    1e-12};
  switch (in->ConsumeIntegralInRange<int>(0, 3)) {
    case 0:
      return kHostile[in->ConsumeIntegralInRange<std::size_t>(0, std::size(kHostile) - 1)];
    case 1:
      return in->ConsumeFloatingPoint<double>();
    default:
      return in->ConsumeFloatingPointInRange<double>(lo, hi);
  }
}

/// A beam range: hostile floats as above (as float: FLT_MAX, denormals, ...) or a value in [0, hi].
inline float hostileRange(FuzzedDataProvider* in, float hi) {
  static const float kHostile[] = {0.0f,
                                   -0.0f,
                                   std::numeric_limits<float>::quiet_NaN(),
                                   std::numeric_limits<float>::infinity(),
                                   -std::numeric_limits<float>::infinity(),
                                   std::numeric_limits<float>::denorm_min(),
                                   FLT_MIN,
                                   FLT_MAX,
                                   -FLT_MAX,
                                   1e7f,
                                   1e30f,
                                   3.4e38f,
                                   -1.0f};
  switch (in->ConsumeIntegralInRange<int>(0, 7)) {
    case 0:
      return kHostile[in->ConsumeIntegralInRange<std::size_t>(0, std::size(kHostile) - 1)];
    case 1:
      return in->ConsumeFloatingPoint<float>();
    default:
      return in->ConsumeFloatingPointInRange<float>(0.0f, hi);
  }
}

/// A stamp's seconds: 2^32 - 1, any value, 0, or a recent date (2023).
inline std::uint32_t hostileSec(FuzzedDataProvider* in) {
  switch (in->ConsumeIntegralInRange<int>(0, 3)) {
    case 0:
      return 4294967295u;
    case 1:
      return in->ConsumeIntegral<std::uint32_t>();
    case 2:
      return 0u;
    default:
      return 1700000000u + in->ConsumeIntegralInRange<std::uint32_t>(0, 100);
  }
}

/// A stamp's nanoseconds: any value (also >= 1e9, which ROS refuses) or a valid one.
inline std::uint32_t hostileNsec(FuzzedDataProvider* in) {
  return in->ConsumeBool() ? in->ConsumeIntegral<std::uint32_t>()
                           : in->ConsumeIntegralInRange<std::uint32_t>(0, 999999999u);
}

}  // namespace wavog_fuzz

#endif  // WAVOG_MAPPING_TEST_FUZZ_FUZZ_SUPPORT_H_
