// Shared names and crop of saved maps (see map_files.h).
#include "wavog_mapping/io/map_files.h"

#include <algorithm>
#include <cstdint>

namespace wavog {

std::string scaleFileBase(const std::string& stem, int scale) {
  return stem + "_s" + std::to_string(scale);
}

std::string pathStem(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  const std::size_t dot = path.find_last_of('.');
  const bool has_ext = dot != std::string::npos && (slash == std::string::npos || dot > slash + 1);
  return has_ext ? path.substr(0, dot) : path;
}

bool knownBox(const Raster& r, CellBox* box) {
  const std::int64_t w = r.box.width();
  const std::int64_t h = r.box.height();
  std::int64_t x0 = w, y0 = h, x1 = -1, y1 = -1;
  for (std::int64_t y = 0; y < h; ++y) {
    const std::uint8_t* row = r.known.data() + static_cast<std::size_t>(y * w);
    for (std::int64_t x = 0; x < w; ++x) {
      if (row[x]) {
        x0 = std::min(x0, x);
        x1 = std::max(x1, x);
        y0 = std::min(y0, y);
        y1 = std::max(y1, y);
      }
    }
  }
  if (x1 < 0) return false;
  *box = CellBox{r.box.min_x + x0, r.box.min_y + y0, r.box.min_x + x1 + 1, r.box.min_y + y1 + 1};
  return true;
}

Raster cropToKnown(const Raster& r, int margin) {
  CellBox k;
  if (!knownBox(r, &k)) return r;
  Raster c;
  c.scale = r.scale;
  c.cell_size = r.cell_size;
  c.box = CellBox{std::max(r.box.min_x, k.min_x - margin), std::max(r.box.min_y, k.min_y - margin),
                  std::min(r.box.max_x, k.max_x + margin), std::min(r.box.max_y, k.max_y + margin)};
  const std::int64_t w = r.box.width();
  const std::int64_t cw = c.box.width();
  const std::int64_t dx = c.box.min_x - r.box.min_x;
  c.log_odds.resize(static_cast<std::size_t>(cw * c.box.height()));
  c.known.resize(c.log_odds.size());
  for (std::int64_t y = 0; y < c.box.height(); ++y) {
    const auto src = static_cast<std::ptrdiff_t>((y + c.box.min_y - r.box.min_y) * w + dx);
    const auto dst = static_cast<std::ptrdiff_t>(y * cw);
    std::copy_n(r.log_odds.begin() + src, cw, c.log_odds.begin() + dst);
    std::copy_n(r.known.begin() + src, cw, c.known.begin() + dst);
  }
  return c;
}

}  // namespace wavog
