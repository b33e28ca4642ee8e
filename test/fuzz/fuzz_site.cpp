// libFuzzer harness: wavog_site's parts without a roscore (site_layers.h, site_vehicles.h), on the
// shards' layers and statuses with every field mutated: up to four OccupancyGrid parts (sizes,
// data shorter or longer than width x height, resolution, rotation, origins near or far from the
// lattice, frames, stamps, any cell value) at any ~max_cells, and up to three shards' FleetStatus.
// Oracles: nothing throws, no undefined behaviour, no write outside the site grid (ASan); a site
// layer is never larger than max_cells; assembled, it holds at each cell the value of the last
// part that knows the cell (-1 where none does), each part's known cells at their lattice place,
// and the oldest part's stamp; refused, it is empty with a reason; the vehicle summary is
// incomplete exactly while a shard is silent, names only vehicles every shard lists, and its
// bound on scans mapped by no shard is the saturating sum of the per-vehicle smallest counts.
#include <nav_msgs/OccupancyGrid.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "fleet/site_layers.h"
#include "fleet/site_vehicles.h"
#include "fuzz_support.h"
#include "wavog_mapping/FleetStatus.h"

namespace {

using wavog_fuzz::hostileDouble;

constexpr std::uint32_t kMaxSide = 48;
const char* const kFrames[] = {"map", "odom", ""};

nav_msgs::OccupancyGrid decodePart(FuzzedDataProvider* in) {
  nav_msgs::OccupancyGrid g;
  g.header.frame_id = kFrames[in->ConsumeIntegralInRange<int>(0, 2) * (in->ConsumeBool() ? 1 : 0)];
  g.header.stamp = ros::Time(in->ConsumeIntegral<std::uint32_t>(),
                             in->ConsumeIntegralInRange<std::uint32_t>(0, 999999999));
  // Mostly the shards' 0.8 m; else any float.
  g.info.resolution = in->ConsumeBool() ? 0.8f : static_cast<float>(hostileDouble(in, -1.0, 4.0));
  g.info.width = in->ConsumeBool() ? in->ConsumeIntegralInRange<std::uint32_t>(0, kMaxSide)
                                   : in->ConsumeIntegral<std::uint32_t>();
  g.info.height = in->ConsumeIntegralInRange<std::uint32_t>(0, kMaxSide);
  // Origins on the lattice of 0.8 m at a small or huge index, or any double.
  for (double* o : {&g.info.origin.position.x, &g.info.origin.position.y}) {
    if (in->ConsumeBool()) {
      const std::int64_t k = in->ConsumeBool()
                                 ? in->ConsumeIntegralInRange<std::int64_t>(-64, 64)
                                 : in->ConsumeIntegralInRange<std::int64_t>(
                                       -(std::int64_t{1} << 42), std::int64_t{1} << 42);
      *o = static_cast<double>(k) * static_cast<double>(0.8f);
    } else {
      *o = hostileDouble(in, -1e4, 1e4);
    }
  }
  g.info.origin.orientation.w = 1.0;
  if (in->ConsumeIntegralInRange<int>(0, 15) == 0) g.info.origin.orientation.z = 0.1;
  // The data: width x height cells (when that is small), or any other count.
  const std::uint64_t cells = static_cast<std::uint64_t>(g.info.width) * g.info.height;
  std::size_t n = cells <= kMaxSide * kMaxSide ? static_cast<std::size_t>(cells) : 0;
  if (in->ConsumeIntegralInRange<int>(0, 7) == 0) {
    n = in->ConsumeIntegralInRange<std::size_t>(0, kMaxSide * kMaxSide);
  }
  g.data.resize(n);
  const bool any_value = in->ConsumeIntegralInRange<int>(0, 7) == 0;
  for (auto& v : g.data) {
    v = any_value ? in->ConsumeIntegral<std::int8_t>()
                  : static_cast<std::int8_t>(in->ConsumeIntegralInRange<int>(-1, 100));
  }
  return g;
}

void checkLayers(FuzzedDataProvider* in) {
  const int n = in->ConsumeIntegralInRange<int>(0, 4);
  std::vector<nav_msgs::OccupancyGrid> grids;
  for (int i = 0; i < n; ++i) grids.push_back(decodePart(in));
  std::vector<const nav_msgs::OccupancyGrid*> parts;
  for (const auto& g : grids)
    parts.push_back(in->ConsumeIntegralInRange<int>(0, 7) == 0 ? nullptr : &g);
  const std::uint64_t max_cells = in->ConsumeBool()
                                      ? wavog_fleet::kDefaultMaxSiteCells
                                      : in->ConsumeIntegralInRange<std::uint64_t>(1, 1u << 16);
  nav_msgs::OccupancyGrid out;
  out.data.assign(3, 7);  // overwritten whatever happens
  std::string why;
  const wavog_fleet::SiteRefusal r = wavog_fleet::assembleSiteLayer(parts, max_cells, &out, &why);
  if (r != wavog_fleet::SiteRefusal::kNone) {
    WAVOG_FUZZ_CHECK(
        out.data.empty() && out.info.width == 0 && out.info.height == 0 && !why.empty(),
        "refused (%d) but %zu cells out, reason '%s'", static_cast<int>(r), out.data.size(),
        why.c_str());
    return;
  }
  const std::uint64_t size = static_cast<std::uint64_t>(out.info.width) * out.info.height;
  WAVOG_FUZZ_CHECK(size == out.data.size() && size <= max_cells && size > 0,
                   "assembled %u x %u, %zu cells, max_cells %llu", out.info.width, out.info.height,
                   out.data.size(), static_cast<unsigned long long>(max_cells));
  const double res = out.info.resolution;
  const std::int64_t ox = std::llround(out.info.origin.position.x / res);
  const std::int64_t oy = std::llround(out.info.origin.position.y / res);
  // The expected site grid: each part's known cells in order (the later wins).
  std::vector<std::int8_t> expected(out.data.size(), -1);
  ros::Time oldest;
  bool any = false;
  for (const auto* g : parts) {
    if (g == nullptr || g->info.width == 0 || g->info.height == 0) continue;
    WAVOG_FUZZ_CHECK(
        g->info.resolution == out.info.resolution && g->header.frame_id == out.header.frame_id,
        "a part of another resolution or frame was assembled");
    if (!any || g->header.stamp < oldest) oldest = g->header.stamp;
    any = true;
    const std::int64_t gx = std::llround(g->info.origin.position.x / res) - ox;
    const std::int64_t gy = std::llround(g->info.origin.position.y / res) - oy;
    WAVOG_FUZZ_CHECK(gx >= 0 && gy >= 0 && gx + g->info.width <= out.info.width &&
                         gy + g->info.height <= out.info.height,
                     "a part at (%lld, %lld) %u x %u outside the site grid %u x %u",
                     static_cast<long long>(gx), static_cast<long long>(gy), g->info.width,
                     g->info.height, out.info.width, out.info.height);
    for (std::uint32_t y = 0; y < g->info.height; ++y) {
      for (std::uint32_t x = 0; x < g->info.width; ++x) {
        const std::int8_t v = g->data[static_cast<std::size_t>(y) * g->info.width + x];
        WAVOG_FUZZ_CHECK(v >= -1 && v <= 100, "value %d assembled", v);
        if (v != -1) {
          expected[static_cast<std::size_t>(gy + y) * out.info.width +
                   static_cast<std::size_t>(gx + x)] = v;
        }
      }
    }
  }
  WAVOG_FUZZ_CHECK(any && out.header.stamp == oldest, "the site layer's stamp is not the oldest");
  WAVOG_FUZZ_CHECK(expected == out.data, "the site grid differs from its parts' known cells");
}

void checkVehicles(FuzzedDataProvider* in) {
  const int shards_n = in->ConsumeIntegralInRange<int>(1, 3);
  std::vector<std::string> shards;
  std::vector<wavog_mapping::FleetStatus::ConstPtr> statuses;
  const char* const names[] = {"/v1", "/v2", "/v3", ""};
  for (int i = 0; i < shards_n; ++i) {
    shards.push_back("/s" + std::to_string(i));
    if (in->ConsumeIntegralInRange<int>(0, 5) == 0) {
      statuses.emplace_back();
      continue;
    }
    wavog_mapping::FleetStatus::Ptr s(new wavog_mapping::FleetStatus);
    const int vn = in->ConsumeIntegralInRange<int>(0, 4);
    for (int k = 0; k < vn; ++k) {
      wavog_mapping::VehicleStatus v;
      v.vehicle = names[in->ConsumeIntegralInRange<int>(0, 3)];
      v.integrated = in->ConsumeIntegralInRange<std::uint64_t>(0, 2);
      v.stale = in->ConsumeBool();
      v.in_region = in->ConsumeBool();
      v.outside_region = in->ConsumeBool() ? in->ConsumeIntegral<std::uint64_t>()
                                           : in->ConsumeIntegralInRange<std::uint64_t>(0, 9);
      v.received = in->ConsumeBool() ? in->ConsumeIntegral<std::uint64_t>()
                                     : in->ConsumeIntegralInRange<std::uint64_t>(0, 9);
      v.lost = in->ConsumeIntegralInRange<std::uint64_t>(0, 3);
      s->vehicles.push_back(v);
    }
    statuses.push_back(s);
  }
  const wavog_fleet::SiteVehicles site = wavog_fleet::summariseVehicles(statuses, shards);
  const bool complete =
      std::all_of(statuses.begin(), statuses.end(), [](const auto& s) { return bool(s); });
  WAVOG_FUZZ_CHECK(site.complete == complete, "complete %d, expected %d", site.complete, complete);
  if (!complete) {
    WAVOG_FUZZ_CHECK(site.outside.empty() && site.scans_mapped_by_none_max == 0,
                     "an incomplete summary names vehicles");
    return;
  }
  // Per vehicle: listed by every shard (by entries); the most scans a shard saw (received +
  // lost), less what a shard mapped (integrated - outside_region), smallest over the shards (a
  // shard's last entry of the vehicle counts).
  using u128 = unsigned __int128;
  std::map<std::string, std::size_t> listed;
  std::vector<std::map<std::string, u128>> seen(statuses.size()), mapped(statuses.size());
  for (std::size_t i = 0; i < statuses.size(); ++i) {
    for (const auto& v : statuses[i]->vehicles) {
      ++listed[v.vehicle];
      seen[i][v.vehicle] =
          std::min<u128>(u128{v.received} + v.lost, std::numeric_limits<std::uint64_t>::max());
      mapped[i][v.vehicle] = v.integrated - std::min(v.integrated, v.outside_region);
    }
  }
  std::map<std::string, u128> sent;
  for (const auto& shard : seen) {
    for (const auto& kv : shard) sent[kv.first] = std::max(sent[kv.first], kv.second);
  }
  u128 sum = 0;
  for (const auto& kv : listed) {
    if (kv.second != statuses.size()) continue;
    u128 fewest = std::numeric_limits<std::uint64_t>::max();
    for (std::size_t i = 0; i < statuses.size(); ++i) {
      const u128 m = mapped[i].count(kv.first) ? mapped[i][kv.first] : 0;
      fewest = std::min(fewest, sent[kv.first] - std::min(sent[kv.first], m));
    }
    sum += fewest;
  }
  const std::uint64_t bound = sum > std::numeric_limits<std::uint64_t>::max()
                                  ? std::numeric_limits<std::uint64_t>::max()
                                  : static_cast<std::uint64_t>(sum);
  WAVOG_FUZZ_CHECK(site.scans_mapped_by_none_max == bound, "bound %llu, expected %llu",
                   static_cast<unsigned long long>(site.scans_mapped_by_none_max),
                   static_cast<unsigned long long>(bound));
  for (const auto& v : site.outside) {
    WAVOG_FUZZ_CHECK(listed.count(v.vehicle) && listed[v.vehicle] == statuses.size(),
                     "vehicle '%s' named outside but not listed by every shard", v.vehicle.c_str());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  checkLayers(&in);
  checkVehicles(&in);
  return 0;
}
