// libFuzzer harness: scan integration with map parameters, poses, beam geometry, ranges and
// clearBox bounds decoded from the bytes (NaN, +-inf, -0, denormals, 1e300, FLT_MAX, ...), then a
// read-out at every scale, stats, save and load.
// Every MapParams option is switched from the bytes (reflection, ndt and its weights,
// forget_half_life across its valid range, num_threads 2), and each scan has its own period.
// Oracles besides the modes': every value read is finite, value() / isObserved() and the payload
// read-outs agree with their scale-0 read-outs, a serial twin (num_threads 1) saves a
// byte-identical file and reads the same, whatever was saved loads and reads back equal (payloads
// included), and a loaded map stays finite after one more scan.
// Two modes, chosen by the first decoded bit:
//  - oracle: a small map (poses within 1 m, range limits up to 3 m, tau = 0) integrated next to
//    the dense cell-by-cell reference (test/core/dense_reference.h); every cell, every coarse
//    scale up to 3, and clearBox (cleared cells back to the prior, the others unchanged) must
//    agree with it; the last bytes may put each scan's sensor on a cell centre, corner or edge,
//    its heading on a multiple of pi / 4 and a sector boundary along it (placeOnLattice; the
//    seeds lattice_* of corpus/fuzz_integrate, made by make_lattice_seeds.py);
//  - hostile: any value anywhere; the contract is only "no crash, no undefined behaviour, bounded
//    work, a consistent read-out and an exact save / load round trip".
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "dense_reference.h"
#include "fuzz_support.h"
#include "reference_oracle.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace {

using wavog::Aggregation;
using wavog::CellBox;
using wavog::MapParams;
using wavog::Pose2;
using wavog::Raster;
using wavog::ScanView;
using wavog::WaveletMap;
using wavog_fuzz::hostileDouble;
using wavog_fuzz::hostileRange;

constexpr double kTwoPi = 6.283185307179586;
constexpr std::size_t kMaxBeams = 720;
constexpr int kMaxScans = 4;
constexpr int kOracleMaxScale = 3;  // coarse scales compared with the reference

struct Scan {
  Pose2 pose;
  std::vector<float> ranges;
  double angle_min = 0, angle_increment = 0, range_min = 0, range_max = 0, period = 0;
  ScanView view() const {
    return ScanView{ranges.data(), ranges.size(), angle_min, angle_increment,
                    range_min,     range_max,     period};
  }
};

using wavog_fuzz::Box;

struct Case {
  bool oracle = false;
  MapParams params;
  std::vector<Scan> scans;
  Box clear;
};

double pick(FuzzedDataProvider* in, std::initializer_list<double> values) {
  const auto i = in->ConsumeIntegralInRange<std::size_t>(0, values.size() - 1);
  return *(values.begin() + static_cast<std::ptrdiff_t>(i));
}

MapParams decodeParams(FuzzedDataProvider* in, bool oracle) {
  const auto type = static_cast<wavog::PolicyType>(in->ConsumeIntegralInRange<int>(0, 5));
  MapParams p = MapParams::defaultsFor(type);
  p.policy.init = in->ConsumeBool() ? wavog::InitValue::kEmptyBound : wavog::InitValue::kUnknown;
  p.lazy_forgetting = in->ConsumeBool();
  p.reflection = in->ConsumeBool();
  p.ndt = in->ConsumeBool();
  p.num_threads = in->ConsumeBool() ? 2 : 1;
  if (p.ndt) {
    p.ndt_min_weight = pick(in, {0.01, 0.0, 1e-9, 0.5, 2.0, 1e6});
    p.ndt_max_weight = pick(in, {100.0, 1.0, 1.5, 3.0, 1e9});
  }
  // forget_half_life: off, or anywhere in (0, 1e6] s, log-uniform, with the ends exactly.
  switch (in->ConsumeIntegralInRange<int>(0, 4)) {
    case 0:
      p.policy.forget_half_life = 0.0;
      break;
    case 1:
      p.policy.forget_half_life = pick(in, {1e6, 1e-9, 409.7, 1000.0, 0.8, 0.81});
      break;
    default:
      p.policy.forget_half_life = std::pow(10.0, in->ConsumeFloatingPointInRange<double>(-4.0, 6.0));
      break;
  }
  if (oracle) {
    p.grid.resolution = pick(in, {0.05, 0.1, 0.2, 0.15});
    p.grid.block_levels = in->ConsumeIntegralInRange<int>(2, 5);
    if (in->ConsumeBool()) {
      p.sensor.odd_occ = in->ConsumeFloatingPointInRange<double>(0.05, 6.0);
      p.sensor.odd_emp = -in->ConsumeFloatingPointInRange<double>(0.05, 6.0);
      p.policy.gamma = in->ConsumeFloatingPointInRange<double>(0.01, 1.0);
      p.policy.clamp_min = -in->ConsumeFloatingPointInRange<double>(0.1, 5.0);
      p.policy.clamp_max = in->ConsumeFloatingPointInRange<double>(0.1, 5.0);
    }
    p.sensor.band_width = in->ConsumeBool() ? 0.0 : in->ConsumeFloatingPointInRange<double>(0, 0.5);
    p.sensor.max_range = in->ConsumeBool() ? 0.0 : in->ConsumeFloatingPointInRange<double>(0, 3.0);
    p.sensor.no_return_clear =
        in->ConsumeBool() ? 0.0 : in->ConsumeFloatingPointInRange<double>(0, 3.0);
    return p;
  }
  // Each parameter is hostile with probability 1/4, else a valid value: a run of invalid ones
  // would almost never reach the integration (the constructor refuses them, which is checked).
  const auto maybe = [in](double valid, double lo, double hi) {
    return in->ConsumeIntegralInRange<int>(0, 3) == 0 ? hostileDouble(in, lo, hi) : valid;
  };
  p.grid.resolution = maybe(pick(in, {0.01, 0.05, 0.1, 0.5, 2.0}), 0.001, 100.0);
  p.grid.block_levels = in->ConsumeIntegralInRange<int>(1, 13);
  p.sensor.odd_occ = maybe(p.sensor.odd_occ, 0.0, 10.0);
  p.sensor.odd_emp = maybe(p.sensor.odd_emp, -10.0, 0.0);
  p.sensor.band_width = maybe(p.sensor.band_width, 0.0, 2.0);
  p.sensor.max_range = maybe(p.sensor.max_range, 0.0, 100.0);
  p.sensor.no_return_clear = maybe(p.sensor.no_return_clear, 0.0, 100.0);
  p.policy.gamma = maybe(p.policy.gamma, 0.0, 1.0);
  p.policy.clamp_min = maybe(p.policy.clamp_min, -10.0, 0.0);
  p.policy.clamp_max = maybe(p.policy.clamp_max, 0.0, 10.0);
  p.prune_threshold = maybe(p.prune_threshold, 0.0, 1.0);
  p.skip_tolerance = maybe(p.skip_tolerance, 0.0, 1.0);
  p.policy.forget_half_life = maybe(p.policy.forget_half_life, 0.0, 1e6);
  p.ndt_min_weight = maybe(p.ndt_min_weight, 0.0, 1e6);
  p.ndt_max_weight = maybe(p.ndt_max_weight, 1.0, 1e9);
  return p;
}

// `resolution`: the map's (hostile ranges drawn in [0, 256 cells], at most 120 m, at least 1 m).
Scan decodeScan(FuzzedDataProvider* in, bool oracle, double resolution) {
  Scan s;
  const std::size_t n = in->ConsumeIntegralInRange<std::size_t>(oracle ? 1 : 0, kMaxBeams);
  if (oracle) {
    s.pose.x = in->ConsumeFloatingPointInRange<double>(-1.0, 1.0);
    s.pose.y = in->ConsumeFloatingPointInRange<double>(-1.0, 1.0);
    s.pose.theta = in->ConsumeFloatingPointInRange<double>(-7.0, 7.0);
    s.angle_min = in->ConsumeFloatingPointInRange<double>(-7.0, 7.0);
    const double fov = in->ConsumeFloatingPointInRange<double>(0.0, kTwoPi);
    s.angle_increment = std::max(fov / static_cast<double>(n), 1e-9) * (in->ConsumeBool() ? 1 : -1);
    s.range_min = in->ConsumeBool() ? 0.0 : in->ConsumeFloatingPointInRange<double>(0.0, 1.0);
    s.range_max = in->ConsumeFloatingPointInRange<double>(0.1, 3.0);
    s.period = in->ConsumeBool() ? pick(in, {0.0, 0.025, 0.1, 1e-7, 1.0, 50.0})
                                 : in->ConsumeFloatingPointInRange<double>(0.0, 2.0);
  } else {
    s.pose.x = hostileDouble(in, -50.0, 50.0);
    s.pose.y = hostileDouble(in, -50.0, 50.0);
    s.pose.theta = hostileDouble(in, -7.0, 7.0);
    s.angle_min = hostileDouble(in, -7.0, 7.0);
    s.angle_increment = hostileDouble(in, -0.1, 0.1);
    s.range_min = hostileDouble(in, 0.0, 1.0);
    s.range_max = hostileDouble(in, 0.0, 100.0);
    s.period = hostileDouble(in, 0.0, 2.0);
  }
  s.ranges.resize(n);
  // Hostile ranges besides the hostile constants: up to 256 cells (a harness speed choice: a
  // 1 cm map with 64 m returns took 0.5 s per input under the sanitizers), every block size
  // still crossed for block_levels up to 8 (the constants and no_return_clear reach further).
  const auto hi = static_cast<float>(oracle ? 4.0 : std::clamp(256.0 * resolution, 1.0, 120.0));
  for (auto& r : s.ranges) r = hostileRange(in, hi);
  return s;
}

// Oracle mode, last (so the bytes of older seeds decode as before, and an input that ends here
// leaves its scans as they are): per scan, the sensor placed on the lattice of cells (a cell
// centre, where its own cell's offset is (0, 0), a corner or an edge), the heading on a multiple
// of pi / 4, and a sector boundary along that heading, through cell centres (issue 42: the
// lookup by table missed the reference's bearing of the offset (0, 0)). Values the continuous
// decoding hits with probability 0, which simulated and quantised poses have.
void placeOnLattice(FuzzedDataProvider* in, double res, Scan* s) {
  const int place = in->ConsumeIntegralInRange<int>(0, 4);  // 0: as decoded
  if (place == 0) return;
  const auto at = [res](double v, bool centre) {
    // As the classifier computes a cell's centre, (i + 1/2) res, and an edge, i res.
    return centre ? (std::floor(v / res) + 0.5) * res : std::round(v / res) * res;
  };
  s->pose.x = at(s->pose.x, place == 1 || place == 3);  // 1 centre, 2 corner, 3 / 4 edges
  s->pose.y = at(s->pose.y, place == 1 || place == 4);
  const int heading = in->ConsumeIntegralInRange<int>(0, 2);
  if (heading == 0) return;
  const double eighth = kTwoPi / 8;
  s->pose.theta = std::round(s->pose.theta / eighth) * eighth;
  if (heading == 2) {  // the boundary between beams j0 and j0 + 1 at sensor bearing 0
    const double last = static_cast<double>(s->ranges.size()) - 1.0;
    const double j0 =
        std::clamp(std::round(-s->angle_min / s->angle_increment - 0.5), 0.0, std::max(last, 0.0));
    s->angle_min = -(j0 + 0.5) * s->angle_increment;
  }
}

Case decode(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  Case c;
  c.oracle = in.ConsumeBool();
  c.params = decodeParams(&in, c.oracle);
  const int scans = in.ConsumeIntegralInRange<int>(1, kMaxScans);
  for (int i = 0; i < scans; ++i) {
    c.scans.push_back(decodeScan(&in, c.oracle, c.params.grid.resolution));
  }
  const double lim = c.oracle ? 5.0 : 100.0;
  if (c.oracle) {
    c.clear = {in.ConsumeFloatingPointInRange<double>(-lim, lim),
               in.ConsumeFloatingPointInRange<double>(-lim, lim),
               in.ConsumeFloatingPointInRange<double>(-lim, lim),
               in.ConsumeFloatingPointInRange<double>(-lim, lim)};
  } else {
    c.clear = {hostileDouble(&in, -lim, lim), hostileDouble(&in, -lim, lim),
               hostileDouble(&in, -lim, lim), hostileDouble(&in, -lim, lim)};
  }
  if (c.oracle) {
    for (auto& s : c.scans) placeOnLattice(&in, c.params.grid.resolution, &s);
  }
  return c;
}

void runOracle(const Case& c, WaveletMap* map) {
  // Everything a scan can reach: poses within 1 m, range limits up to 3 m, half a band of 0.25 m.
  const auto cells = static_cast<std::int64_t>(std::ceil(4.5 / c.params.grid.resolution)) + 2;
  wavog_test::DenseReference ref(c.params, CellBox{-cells, -cells, cells, cells});
  for (const auto& s : c.scans) {
    ref.setGamma(0, map->forgetRate(s.period));  // the rate the map applies to this scan
    map->integrate(s.pose, s.view());
    ref.integrate(s.pose, s.view());
  }
  wavog_fuzz::expectCellsEqual(*map, ref, nullptr, "after the scans");
  wavog_fuzz::expectScalesEqual(*map, ref, kOracleMaxScale);
  map->clearBox(c.clear.min_x, c.clear.min_y, c.clear.max_x, c.clear.max_y);
  wavog_fuzz::expectCellsEqual(*map, ref, &c.clear, "after clearBox");
  // Nothing outside the reference's extent was written.
  CellBox b;
  if (map->bounds(0, &b)) {
    const std::int64_t block = std::int64_t{1} << c.params.grid.block_levels;
    WAVOG_FUZZ_CHECK(b.min_x >= -cells - block && b.max_x <= cells + block &&
                         b.min_y >= -cells - block && b.max_y <= cells + block,
                     "blocks beyond the scans' reach: [%lld, %lld) x [%lld, %lld)",
                     static_cast<long long>(b.min_x), static_cast<long long>(b.max_x),
                     static_cast<long long>(b.min_y), static_cast<long long>(b.max_y));
  }
}

// WAVOG_FUZZ_DESCRIBE=1: prints the decoded case (to turn a finding into a unit test).
void describe(const Case& c) {
  const MapParams& p = c.params;
  std::fprintf(stderr,
               "case: %s; resolution %.17g block_levels %d policy %s init %s lazy %d threads %d\n"
               "  reflection %d ndt %d [%.17g, %.17g] half-life %.17g\n"
               "  odd_occ %.17g odd_emp %.17g band_width %.17g max_range %.17g "
               "no_return_clear %.17g\n  gamma %.17g clamp [%.17g, %.17g] prune %.17g skip %.17g\n",
               c.oracle ? "oracle" : "hostile", p.grid.resolution, p.grid.block_levels,
               wavog::toString(p.policy.type), wavog::toString(p.policy.init), p.lazy_forgetting,
               p.num_threads, p.reflection, p.ndt, p.ndt_min_weight, p.ndt_max_weight,
               p.policy.forget_half_life,
               p.sensor.odd_occ, p.sensor.odd_emp, p.sensor.band_width, p.sensor.max_range,
               p.sensor.no_return_clear, p.policy.gamma, p.policy.clamp_min, p.policy.clamp_max,
               p.prune_threshold, p.skip_tolerance);
  for (const auto& s : c.scans) {
    std::fprintf(stderr,
                 "  scan: pose (%.17g, %.17g, %.17g) angle_min %.17g increment %.17g range "
                 "[%.17g, %.17g] period %.17g %zu beams:",
                 s.pose.x, s.pose.y, s.pose.theta, s.angle_min, s.angle_increment, s.range_min,
                 s.range_max, s.period, s.ranges.size());
    for (float r : s.ranges) std::fprintf(stderr, " %.9g", static_cast<double>(r));
    std::fprintf(stderr, "\n");
  }
  std::fprintf(stderr, "  clearBox [%.17g, %.17g] x [%.17g, %.17g]\n", c.clear.min_x, c.clear.max_x,
               c.clear.min_y, c.clear.max_y);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const Case c = decode(data, size);
  static const bool describe_cases = std::getenv("WAVOG_FUZZ_DESCRIBE") != nullptr;
  if (describe_cases) describe(c);
  if (!c.params.validate().empty()) {
    bool threw = false;
    try {
      WaveletMap refused(c.params);
    } catch (const std::invalid_argument&) {
      threw = true;
    }
    WAVOG_FUZZ_CHECK(threw, "invalid parameters accepted");
    return 0;
  }
  WaveletMap map(c.params);
  if (c.oracle) {
    runOracle(c, &map);
  } else {
    for (const auto& s : c.scans) {
      const auto st = map.integrate(s.pose, s.view());
      if (st.status == wavog::ScanStatus::kOk) {
        WAVOG_FUZZ_CHECK(st.beams_hit + st.beams_no_return + st.beams_invalid == s.ranges.size(),
                         "%u + %u + %u beams counted of %zu", st.beams_hit, st.beams_no_return,
                         st.beams_invalid, s.ranges.size());
      }
    }
    map.clearBox(c.clear.min_x, c.clear.min_y, c.clear.max_x, c.clear.max_y);
  }

  const auto rasters = wavog_fuzz::readOutEveryScale(map);
  const auto payloads = wavog_fuzz::readPayloads(map);
  const auto st = map.stats(true);
  WAVOG_FUZZ_CHECK(st.bytes <= st.bytes_reserved, "stats: %zu bytes > %zu reserved", st.bytes,
                   st.bytes_reserved);
  static const std::string path = wavog_fuzz::scratchPath("integrate.wavog");
  map.save(path);
  if (c.params.num_threads != 1) {
    // The serial twin: the same scans on one thread save the same bytes.
    MapParams serial = c.params;
    serial.num_threads = 1;
    WaveletMap twin(serial);
    for (const auto& s : c.scans) twin.integrate(s.pose, s.view());
    twin.clearBox(c.clear.min_x, c.clear.min_y, c.clear.max_x, c.clear.max_y);
    static const std::string twin_path = wavog_fuzz::scratchPath("twin.wavog");
    twin.save(twin_path);
    WAVOG_FUZZ_CHECK(wavog_fuzz::readFile(path) == wavog_fuzz::readFile(twin_path),
                     "the threaded map's file differs from its serial twin's");
  }
  WaveletMap loaded(c.params);
  try {
    loaded.load(path);
  } catch (const wavog::MapIoError& e) {
    WAVOG_FUZZ_CHECK(false, "a saved map does not load: %s", e.what());
  }
  WAVOG_FUZZ_CHECK(wavog_fuzz::readPayloads(loaded) == payloads,
                   "round trip: the payload read-outs differ");
  const auto again = wavog_fuzz::readOutEveryScale(loaded);
  WAVOG_FUZZ_CHECK(rasters.size() == again.size(), "round trip: %zu vs %zu rasters", rasters.size(),
                   again.size());
  for (std::size_t i = 0; i < rasters.size(); ++i) {
    WAVOG_FUZZ_CHECK(wavog_fuzz::sameBits(rasters[i], again[i]), "round trip: raster %zu differs",
                     i);
  }
  WAVOG_FUZZ_CHECK(loaded.stats(true).observed_cells == st.observed_cells,
                   "round trip: %llu vs %llu observed cells",
                   static_cast<unsigned long long>(loaded.stats(true).observed_cells),
                   static_cast<unsigned long long>(st.observed_cells));
  // The loaded map takes one more scan and stays finite (readOutEveryScale checks), and saves.
  loaded.integrate(c.scans[0].pose, c.scans[0].view());
  (void)wavog_fuzz::readOutEveryScale(loaded);
  (void)wavog_fuzz::readPayloads(loaded);
  loaded.save(path);
  return 0;
}
