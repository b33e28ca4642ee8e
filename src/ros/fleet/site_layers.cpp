// assembleSiteLayer (see site_layers.h).
#include "site_layers.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace wavog_fleet {
namespace {

// The cell index of a grid origin coordinate on the lattice of cell size `res`.
bool latticeIndex(double origin, double res, std::int64_t* index) {
  const double k = origin / res;
  const double r = std::round(k);
  if (!std::isfinite(k) || std::abs(k - r) > 1e-3 || std::abs(r) > 1e15) return false;
  *index = static_cast<std::int64_t>(r);
  return true;
}

}  // namespace

bool assembleSiteLayer(const std::vector<const nav_msgs::OccupancyGrid*>& parts,
                       nav_msgs::OccupancyGrid* out, std::string* why) {
  *out = nav_msgs::OccupancyGrid();
  struct Part {
    const nav_msgs::OccupancyGrid* grid;
    std::int64_t x0, y0;
  };
  std::vector<Part> known;
  double res = 0.0;
  std::int64_t min_x = std::numeric_limits<std::int64_t>::max(), min_y = min_x;
  std::int64_t max_x = std::numeric_limits<std::int64_t>::min(), max_y = max_x;
  for (const nav_msgs::OccupancyGrid* g : parts) {
    if (g == nullptr || g->info.width == 0 || g->info.height == 0) continue;
    if (g->data.size() != static_cast<std::size_t>(g->info.width) * g->info.height) {
      *why = "a layer's data does not match its width x height";
      return false;
    }
    if (known.empty()) {
      res = g->info.resolution;
      out->header = g->header;
    } else if (g->info.resolution != res || g->header.frame_id != out->header.frame_id) {
      *why = "the shards' layers differ in resolution or frame";
      return false;
    }
    if (g->header.stamp < out->header.stamp) out->header.stamp = g->header.stamp;
    Part p{g, 0, 0};
    if (!latticeIndex(g->info.origin.position.x, res, &p.x0) ||
        !latticeIndex(g->info.origin.position.y, res, &p.y0)) {
      *why = "a layer's origin is not on the cell lattice";
      return false;
    }
    min_x = std::min(min_x, p.x0);
    min_y = std::min(min_y, p.y0);
    max_x = std::max(max_x, p.x0 + static_cast<std::int64_t>(g->info.width));
    max_y = std::max(max_y, p.y0 + static_cast<std::int64_t>(g->info.height));
    known.push_back(p);
  }
  if (known.empty()) {
    *why = "no shard has published a known cell yet";
    return false;
  }
  out->info.resolution = static_cast<float>(res);
  out->info.width = static_cast<std::uint32_t>(max_x - min_x);
  out->info.height = static_cast<std::uint32_t>(max_y - min_y);
  out->info.origin.position.x = static_cast<double>(min_x) * res;
  out->info.origin.position.y = static_cast<double>(min_y) * res;
  out->info.origin.orientation.w = 1.0;
  out->info.map_load_time = out->header.stamp;
  out->data.assign(static_cast<std::size_t>(out->info.width) * out->info.height, -1);
  for (const Part& p : known) {
    const auto& g = *p.grid;
    for (std::uint32_t y = 0; y < g.info.height; ++y) {
      const std::size_t row = static_cast<std::size_t>(p.y0 - min_y + y) * out->info.width +
                              static_cast<std::size_t>(p.x0 - min_x);
      for (std::uint32_t x = 0; x < g.info.width; ++x) {
        const std::int8_t v = g.data[static_cast<std::size_t>(y) * g.info.width + x];
        if (v != -1) out->data[row + x] = v;
      }
    }
  }
  return true;
}

}  // namespace wavog_fleet
