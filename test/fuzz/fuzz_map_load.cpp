// libFuzzer harness: the native map loader (WaveletMap::load) on arbitrary bytes, then a read-out
// of the loaded map at every scale, its stats, and a save / load round trip.
// Input: one mode byte, then the file. Mode bit 0 set: the rest is the content behind the header
// (resolution onwards), framed with the magic, version and a valid CRC-32, so that mutations
// reach the parser behind the checksum; clear: the rest is the file as it is. Bits 1-2: the
// loading map's policy (clamp, or forgetting with one of three gammas, so a file's pending
// forgetting tags are sometimes applied while loading).
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
constexpr std::uint32_t kVersion = 1;

std::vector<std::uint8_t> frame(const std::uint8_t* body, std::size_t size) {
  std::vector<std::uint8_t> out(kMagic, kMagic + sizeof(kMagic));
  const auto* v = reinterpret_cast<const std::uint8_t*>(&kVersion);
  out.insert(out.end(), v, v + sizeof(kVersion));
  out.insert(out.end(), body, body + size);
  const auto crc = static_cast<std::uint32_t>(crc32(0L, out.data(), static_cast<uInt>(out.size())));
  const auto* c = reinterpret_cast<const std::uint8_t*>(&crc);
  out.insert(out.end(), c, c + sizeof(crc));
  return out;
}

// Parameters the file can be loaded with: its own resolution and block_levels when they are
// valid (otherwise the load is refused at once, which is tested as well).
MapParams paramsFor(const std::vector<std::uint8_t>& file, std::uint8_t mode) {
  const int policy = (mode >> 1) & 3;
  MapParams p =
      MapParams::defaultsFor(policy == 0 ? wavog::PolicyType::kClamp : wavog::PolicyType::kForget);
  static const double kGamma[] = {0.3, 0.3, 0.5, 1.0};
  p.policy.gamma = kGamma[policy];
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

bool sameBits(const Raster& a, const Raster& b) {
  return a.scale == b.scale && a.box.min_x == b.box.min_x && a.box.min_y == b.box.min_y &&
         a.box.max_x == b.box.max_x && a.box.max_y == b.box.max_y && a.known == b.known &&
         a.log_odds.size() == b.log_odds.size() &&
         std::memcmp(a.log_odds.data(), b.log_odds.data(), a.log_odds.size() * sizeof(float)) == 0;
}

// Every scale over the map's bounds, both aggregations; returns the rasters.
std::vector<Raster> readOut(const WaveletMap& map) {
  std::vector<Raster> out;
  for (int s = 0; s <= map.params().grid.block_levels; ++s) {
    CellBox box;
    if (!map.bounds(s, &box)) break;
    if (!wavog::readoutFits(box)) {
      wavog_fuzz::expectReadOutRefused(map, s, box);
      continue;
    }
    box = wavog_fuzz::readOutWindow(box);
    for (Aggregation agg : {Aggregation::kMean, Aggregation::kMax}) {
      Raster r = map.exportScale(s, box, agg);
      const auto cells =
          static_cast<std::size_t>(box.width()) * static_cast<std::size_t>(box.height());
      WAVOG_FUZZ_CHECK(r.log_odds.size() == cells && r.known.size() == cells,
                       "scale %d: raster of %zu cells for a %lld x %lld window", s,
                       r.log_odds.size(), static_cast<long long>(box.width()),
                       static_cast<long long>(box.height()));
      const auto grid = wavog::toOccupancyGrid(r);
      for (std::size_t i = 0; i < grid.size(); ++i) {
        WAVOG_FUZZ_CHECK(grid[i] >= -1 && grid[i] <= 100, "occupancy %d", grid[i]);
        WAVOG_FUZZ_CHECK((grid[i] == -1) == (r.known[i] == 0) || std::isnan(r.log_odds[i]),
                         "known flag and occupancy disagree at %zu", i);
      }
      out.push_back(std::move(r));
    }
  }
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t mode = data[0];
  const std::vector<std::uint8_t> file =
      (mode & 1) ? frame(data + 1, size - 1) : std::vector<std::uint8_t>(data + 1, data + size);
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
    return 0;
  }
  const auto rasters = readOut(map);
  const auto st = map.stats(true);
  WAVOG_FUZZ_CHECK(st.bytes <= st.bytes_reserved, "stats: %zu bytes > %zu reserved", st.bytes,
                   st.bytes_reserved);

  // Round trip: the loaded map saved and loaded again reads out bit for bit the same.
  map.save(again_path);
  WaveletMap again(params);
  again.load(again_path);
  const auto rasters_again = readOut(again);
  WAVOG_FUZZ_CHECK(rasters.size() == rasters_again.size(), "round trip: %zu vs %zu rasters",
                   rasters.size(), rasters_again.size());
  for (std::size_t i = 0; i < rasters.size(); ++i) {
    WAVOG_FUZZ_CHECK(sameBits(rasters[i], rasters_again[i]), "round trip: raster %zu differs", i);
  }
  WAVOG_FUZZ_CHECK(again.stats().blocks == st.blocks && again.stats().nodes == st.nodes,
                   "round trip: %zu/%zu blocks, %zu/%zu nodes", again.stats().blocks, st.blocks,
                   again.stats().nodes, st.nodes);
  return 0;
}
