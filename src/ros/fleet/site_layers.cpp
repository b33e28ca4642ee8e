// assembleSiteLayer (see site_layers.h).
#include "site_layers.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

namespace wavog_fleet {
namespace {

// Origins farther than this many cells from the frame's origin are refused (2^40 cells: beyond
// any site at any resolution; keeps every index sum below in int64).
constexpr double kMaxLatticeIndex = 1099511627776.0;

// The cell index of a grid origin coordinate on the lattice of cell size `res`.
bool latticeIndex(double origin, double res, std::int64_t* index) {
  const double k = origin / res;
  const double r = std::round(k);
  if (!std::isfinite(k) || std::abs(k - r) > 1e-3 || std::abs(r) > kMaxLatticeIndex) return false;
  *index = static_cast<std::int64_t>(r);
  return true;
}

// The shards publish their layers unrotated (orientation the identity quaternion).
bool unrotated(const geometry_msgs::Quaternion& q) {
  return std::abs(q.x) < 1e-9 && std::abs(q.y) < 1e-9 && std::abs(q.z) < 1e-9 &&
         std::abs(q.w - 1.0) < 1e-9;
}

SiteRefusal refuse(SiteRefusal r, std::string text, nav_msgs::OccupancyGrid* out,
                   std::string* why) {
  *out = nav_msgs::OccupancyGrid();
  *why = std::move(text);
  return r;
}

}  // namespace

SiteRefusal assembleSiteLayer(const std::vector<const nav_msgs::OccupancyGrid*>& parts,
                              std::uint64_t max_cells, nav_msgs::OccupancyGrid* out,
                              std::string* why) {
  *out = nav_msgs::OccupancyGrid();
  struct Part {
    const nav_msgs::OccupancyGrid* grid;
    std::int64_t x0, y0;
  };
  std::vector<Part> known;
  double res = 0.0;
  std::int64_t min_x = std::numeric_limits<std::int64_t>::max(), min_y = min_x;
  std::int64_t max_x = std::numeric_limits<std::int64_t>::min(), max_y = max_x;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const nav_msgs::OccupancyGrid* g = parts[i];
    if (g == nullptr || g->info.width == 0 || g->info.height == 0) continue;
    const std::string name = "shard " + std::to_string(i) + "'s layer";
    if (g->data.size() != static_cast<std::size_t>(g->info.width) * g->info.height) {
      return refuse(SiteRefusal::kBadLayer,
                    name + ": data holds " + std::to_string(g->data.size()) +
                        " cells, width x height " + std::to_string(g->info.width) + " x " +
                        std::to_string(g->info.height),
                    out, why);
    }
    if (!(std::isfinite(g->info.resolution) && g->info.resolution > 0.0f)) {
      return refuse(
          SiteRefusal::kBadLayer,
          name + ": resolution " + std::to_string(g->info.resolution) + " is not a positive number",
          out, why);
    }
    if (!unrotated(g->info.origin.orientation)) {
      return refuse(SiteRefusal::kBadLayer, name + ": origin is rotated (shards publish unrotated)",
                    out, why);
    }
    if (known.empty()) {
      res = g->info.resolution;
      out->header = g->header;
    } else if (g->info.resolution != res || g->header.frame_id != out->header.frame_id) {
      return refuse(SiteRefusal::kMismatch,
                    name + " differs from the others in resolution or frame ('" +
                        g->header.frame_id + "' at " + std::to_string(g->info.resolution) +
                        " m, others '" + out->header.frame_id + "' at " + std::to_string(res) +
                        " m)",
                    out, why);
    }
    if (g->header.stamp < out->header.stamp) out->header.stamp = g->header.stamp;
    Part p{g, 0, 0};
    if (!latticeIndex(g->info.origin.position.x, res, &p.x0) ||
        !latticeIndex(g->info.origin.position.y, res, &p.y0)) {
      return refuse(SiteRefusal::kMismatch,
                    name + ": origin is not on the others' cell lattice (or beyond 2^40 cells)",
                    out, why);
    }
    min_x = std::min(min_x, p.x0);
    min_y = std::min(min_y, p.y0);
    max_x = std::max(max_x, p.x0 + static_cast<std::int64_t>(g->info.width));
    max_y = std::max(max_y, p.y0 + static_cast<std::int64_t>(g->info.height));
    known.push_back(p);
  }
  if (known.empty()) {
    return refuse(SiteRefusal::kNothingKnown, "no shard has published a known cell yet", out, why);
  }
  // Each side below 2^41 + 2^32 (lattice bound): compare in double before multiplying.
  const double width = static_cast<double>(max_x - min_x);
  const double height = static_cast<double>(max_y - min_y);
  if (width * height > static_cast<double>(max_cells)) {
    return refuse(SiteRefusal::kTooLarge,
                  "the shards' layers span " + std::to_string(static_cast<std::uint64_t>(width)) +
                      " x " + std::to_string(static_cast<std::uint64_t>(height)) +
                      " cells, over ~max_cells (" + std::to_string(max_cells) + ")",
                  out, why);
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
        if (v < -1 || v > 100) {
          return refuse(SiteRefusal::kBadLayer,
                        "a shard's layer holds the value " + std::to_string(v) +
                            " (an occupancy grid holds -1 or 0 to 100)",
                        out, why);
        }
        if (v != -1) out->data[row + x] = v;
      }
    }
  }
  return SiteRefusal::kNone;
}

}  // namespace wavog_fleet
