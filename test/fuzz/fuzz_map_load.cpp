// libFuzzer harness: the native map loader (WaveletMap::load) on arbitrary bytes, then a read-out
// of the loaded map at every scale, its stats, and a save / load round trip.
// Input: one mode byte, then the file. Mode bit 0 set: the rest is the content behind the header
// (resolution onwards), framed with the magic, version and a valid CRC-32, so that mutations
// reach the parser behind the checksum; clear: the rest is the file as it is. Bits 1-2: the
// loading map's policy (clamp, or forgetting with one of three gammas, so a file's pending
// forgetting tags are sometimes applied while loading). Bits 3 and 6: the framed version, 5 and
// then the same content as 6, the current one (neither: loaded twice, f32 then f64 details;
// 4, unbounded clamp counts, with the clamp policy and bit 4), 1 (bit 3: u8 pending
// counts), 2 (bit 6: no NDT section) or 3 (both: no hits section). Bit 4: forgetting with
// forget_half_life (16-bit pending units). Bit 5: the loading
// map keeps normal-distribution cells (MapParams::ndt). Bit 7: it keeps a reflection map
// (MapParams::reflection).
// Oracles: a refused load leaves the map empty; a loaded map reads finite values, value() and
// isObserved() agree with the scale-0 read-out, its payload read-outs agree with their point
// queries, it saves and loads again reading the same (payloads
// included), and it takes one ordinary scan staying finite (issue 28: a file with a block average
// of -1e57 loaded and turned NaN) and saving a file that loads (issue 42; seed at_bound_details:
// every block average and detail at the bound 1e30).
#include <zlib.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "fuzz_support.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace {

using wavog::Aggregation;
using wavog::CellBox;
using wavog::MapParams;
using wavog::Raster;
using wavog::WaveletMap;

constexpr char kMagic[8] = {'W', 'A', 'V', 'O', 'G', 'M', 'A', 'P'};

std::vector<std::uint8_t> frame(const std::uint8_t* body, std::size_t size, std::uint32_t version) {
  std::vector<std::uint8_t> out(kMagic, kMagic + sizeof(kMagic));
  const auto* v = reinterpret_cast<const std::uint8_t*>(&version);
  out.insert(out.end(), v, v + sizeof(version));
  out.insert(out.end(), body, body + size);
  const auto crc = static_cast<std::uint32_t>(crc32(0L, out.data(), static_cast<uInt>(out.size())));
  const auto* c = reinterpret_cast<const std::uint8_t*>(&crc);
  out.insert(out.end(), c, c + sizeof(crc));
  return out;
}

std::uint32_t framedVersion(std::uint8_t mode) {
  const bool b3 = (mode & 8) != 0, b6 = (mode & 64) != 0;
  const bool clamp_v4 = ((mode >> 1) & 3) == 0 && (mode & 16) != 0;
  return b3 ? (b6 ? 3 : 1) : (b6 ? 2 : (clamp_v4 ? 4 : 5));
}

// Parameters the file can be loaded with: its own resolution and block_levels when they are
// valid (otherwise the load is refused at once, which is tested as well).
MapParams paramsFor(const std::vector<std::uint8_t>& file, std::uint8_t mode) {
  const int policy = (mode >> 1) & 3;
  MapParams p =
      MapParams::defaultsFor(policy == 0 ? wavog::PolicyType::kClamp : wavog::PolicyType::kForget);
  static const double kGamma[] = {0.3, 0.3, 0.5, 1.0};
  p.policy.gamma = kGamma[policy];
  // forget_half_life: 0.3 s (2^-11 units), or long ones (finer units), by the file's size.
  static const double kHalfLife[] = {0.3, 1000.0, 1e6};
  if (policy != 0 && (mode & 16)) p.policy.forget_half_life = kHalfLife[file.size() % 3];
  p.ndt = (mode & 32) != 0;
  p.reflection = (mode & 128) != 0;
  if (file.size() >= 24) {
    MapParams q = p;
    std::memcpy(&q.grid.resolution, file.data() + 12, sizeof(double));
    std::int32_t levels;
    std::memcpy(&levels, file.data() + 20, sizeof(levels));
    q.grid.block_levels = levels;
    if (q.validate().empty()) p = q;
  }
  return p;
}

// One file through the loader and the oracles.
void loadAndCheck(const std::vector<std::uint8_t>& file, std::uint8_t mode) {
  const MapParams params = paramsFor(file, mode);
  static const std::string path = wavog_fuzz::scratchPath("load.wavog");
  static const std::string again_path = wavog_fuzz::scratchPath("again.wavog");
  wavog_fuzz::writeFile(path, file.data(), file.size());

  WaveletMap map(params);
  try {
    map.load(path);
  } catch (const wavog::MapIoError&) {
    // Refused, with a message: the map must be left as it was (empty).
    WAVOG_FUZZ_CHECK(map.stats().blocks == 0, "a refused load changed the map");
    return;
  }
  const auto rasters = wavog_fuzz::readOutEveryScale(map);
  const auto payloads = wavog_fuzz::readPayloads(map);
  const auto st = map.stats(true);
  WAVOG_FUZZ_CHECK(st.bytes <= st.bytes_reserved, "stats: %zu bytes > %zu reserved", st.bytes,
                   st.bytes_reserved);

  // Round trip: the loaded map saved and loaded again reads out bit for bit the same.
  map.save(again_path);
  WaveletMap again(params);
  try {
    again.load(again_path);
  } catch (const wavog::MapIoError& e) {
    WAVOG_FUZZ_CHECK(false, "a saved map does not load: %s", e.what());
  }
  WAVOG_FUZZ_CHECK(wavog_fuzz::readPayloads(again) == payloads,
                   "round trip: the payload read-outs differ");
  const auto rasters_again = wavog_fuzz::readOutEveryScale(again);
  WAVOG_FUZZ_CHECK(rasters.size() == rasters_again.size(), "round trip: %zu vs %zu rasters",
                   rasters.size(), rasters_again.size());
  for (std::size_t i = 0; i < rasters.size(); ++i) {
    WAVOG_FUZZ_CHECK(wavog_fuzz::sameBits(rasters[i], rasters_again[i]),
                     "round trip: raster %zu differs", i);
  }
  WAVOG_FUZZ_CHECK(again.stats().blocks == st.blocks && again.stats().nodes == st.nodes,
                   "round trip: %zu/%zu blocks, %zu/%zu nodes", again.stats().blocks, st.blocks,
                   again.stats().nodes, st.nodes);
  // One ordinary scan (a half circle of 2 m returns at 10 Hz from the first block's area) keeps
  // every value finite, and the map still saves a file that loads (issue 42: next to a file's
  // cells beyond the bound, a scan wrote details beyond it, which the loader refuses).
  CellBox b;
  if (map.bounds(0, &b)) {
    const double res = params.grid.resolution;
    const wavog::Pose2 pose{static_cast<double>(b.min_x) * res + 1.0,
                            static_cast<double>(b.min_y) * res + 1.0, 0.0};
    static const std::vector<float> ranges(181, 2.0f);
    const wavog::ScanView scan{ranges.data(), ranges.size(), -1.5707963267948966,
                               3.14159265358979 / 180, 0.05, 30.0, 0.1};
    map.integrate(pose, scan);
    (void)wavog_fuzz::readOutEveryScale(map);
    (void)wavog_fuzz::readPayloads(map);
    map.save(again_path);
    WaveletMap scanned(params);
    try {
      scanned.load(again_path);
    } catch (const wavog::MapIoError& e) {
      WAVOG_FUZZ_CHECK(false, "the map saved after a scan does not load: %s", e.what());
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t mode = data[0];
  if (!(mode & 1)) {
    loadAndCheck(std::vector<std::uint8_t>(data + 1, data + size), mode);
    return 0;
  }
  const std::uint32_t version = framedVersion(mode);
  loadAndCheck(frame(data + 1, size - 1, version), mode);
  // Version 5 differs from the current 6 only in the width of the details: the same content is
  // a hostile version-6 file too (a file of blocks without subtrees loads as both).
  if (version == 5) loadAndCheck(frame(data + 1, size - 1, 6), mode);
  return 0;
}
