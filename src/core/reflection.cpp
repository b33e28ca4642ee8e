// The reflection probability map (MapParams::reflection; paper section 1.2.2, eq. 1.3): the hits
// and misses of every cell are two more maps of the same kind, with the map's policy and odd
// values that count: hits add 1 in the occupied band and 0 in free space, misses the other way
// round. They are integrated with the main map's classification of each scan (integrate.cpp), so
// coarse E updates stay coarse and forgetting stays lazy; p at scale s is the ratio of their Haar
// averages, exact at every scale.
#include <cmath>
#include <limits>
#include <stdexcept>

#include "map_impl.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog {

MapParams WaveletMap::Impl::layerParams(const MapParams& main, bool hits) {
  MapParams p = main;
  p.reflection = false;
  p.ndt = false;
  p.policy.init = InitValue::kUnknown;  // no count yet
  // Forgetting forgets the counts by the map's gamma; every other policy counts (see params.h).
  p.policy.type = main.policy.type == PolicyType::kForget ? PolicyType::kForget : PolicyType::kNone;
  p.sensor.odd_occ = hits ? 1.0 : 0.0;
  p.sensor.odd_emp = hits ? 0.0 : 1.0;
  return p;
}

void WaveletMap::Impl::configureLayers() {
  if (!params.reflection) return;
  const bool with_misses = params.policy.type != PolicyType::kMax;  // "max": hits only
  const auto update = [](std::unique_ptr<WaveletMap>* layer, const MapParams& p) {
    if (!*layer) {
      layer->reset(new WaveletMap(p, LayerTag{}));
      return;
    }
    Impl& impl = *(*layer)->impl_;
    impl.flushAll();  // pending counts stand for the old factor
    impl.params = p;
    impl.configure();
  };
  update(&hits, layerParams(params, true));
  if (with_misses) {
    update(&misses, layerParams(params, false));
  } else {
    misses.reset();
  }
}

namespace {

// p from the hits and misses averages of one cell or raster cell.
float probability(bool known, double h, const WaveletMap* misses, double m) {
  if (!known) return std::numeric_limits<float>::quiet_NaN();
  if (misses == nullptr) return h > 0.0 ? 1.0f : 0.0f;
  const double total = h + m;  // float details may leave a count a hair below 0
  if (!(total > 0.0)) return std::numeric_limits<float>::quiet_NaN();
  return static_cast<float>(std::fmin(1.0, std::fmax(0.0, h / total)));
}

const WaveletMap& hitsOf(const WaveletMap::Impl& impl) {
  if (!impl.hits)
    throw std::logic_error("this map keeps no reflection layer (MapParams::reflection)");
  return *impl.hits;
}

}  // namespace

ReflectionRaster WaveletMap::exportReflection(int scale, const CellBox& window) const {
  const WaveletMap& hits = hitsOf(*impl_);
  const WaveletMap* misses = impl_->misses.get();
  // Hits and misses share the main map's classification, so their knowledge is the same.
  const Raster h = hits.exportScale(scale, window, Aggregation::kMean);
  Raster m;
  if (misses != nullptr) m = misses->exportScale(scale, window, Aggregation::kMean);
  ReflectionRaster r;
  r.scale = h.scale;
  r.cell_size = h.cell_size;
  r.box = h.box;
  r.p.resize(h.log_odds.size());
  for (std::size_t i = 0; i < r.p.size(); ++i) {
    r.p[i] = probability(h.known[i] != 0, h.log_odds[i], misses,
                         misses != nullptr ? m.log_odds[i] : 0.0);
  }
  return r;
}

float WaveletMap::reflection(const CellIndex& cell) const {
  const WaveletMap& hits = hitsOf(*impl_);
  const WaveletMap* misses = impl_->misses.get();
  return probability(hits.isObserved(cell), hits.value(cell), misses,
                     misses != nullptr ? misses->value(cell) : 0.0);
}

std::vector<std::int8_t> toOccupancyGrid(const ReflectionRaster& raster) {
  std::vector<std::int8_t> out(raster.p.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const float p = raster.p[i];
    out[i] = std::isnan(p) ? std::int8_t{-1} : static_cast<std::int8_t>(std::lround(100.0f * p));
  }
  return out;
}

}  // namespace wavog
