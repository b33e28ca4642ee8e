// The reflection probability map (MapParams::reflection; paper section 1.2.2, eq. 1.3): p = h /
// (h + m) from the hits h (beams that ended in a cell: the occupied band) and misses m (beams
// that crossed it: E cells) of every cell, under the map's policy. Hits are kept only for the
// cells that were hit (reflection_store.h, updated by reflection_update.h); misses are read from
// the occupancy itself wherever it is a linear function of the counts, which it is when the map
// has applied "none", or "forget", with the same odd values and prior since it was empty
// (ReflectionBasis; docs/algorithm.md). So free space costs nothing more to update. The clamps
// are not linear: their misses are counted in a layer, another map of the same kind integrated
// with the main map's classification of each scan. p at scale s is the ratio of the sums over
// the cells under each coarse cell, exact at every scale.
#include <cmath>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "storage/cell_reader.h"
#include "storage/map_impl.h"
#include "wavog_mapping/core/limits.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog {

using detail::Block;

MapParams WaveletMap::Impl::layerParams(const MapParams& main, bool hits, ReflectionMode mode) {
  MapParams p = main;
  p.reflection = false;
  p.ndt = false;
  // Forgetting forgets the counts by the map's gamma; every other policy counts (see params.h).
  const bool forget = mode == ReflectionMode::kLayers && main.policy.type == PolicyType::kForget;
  p.policy.type = forget ? PolicyType::kForget : PolicyType::kNone;
  // No count yet; with forgetting and the empty_bound prior, a cell starts as one full miss (its
  // empty bound, as the occupancy does): h + m = 1.
  p.policy.init = forget && !hits ? main.policy.init : InitValue::kUnknown;
  p.sensor.odd_occ = hits ? 1.0 : 0.0;
  p.sensor.odd_emp = hits ? 0.0 : 1.0;
  if (!hits && mode == ReflectionMode::kCounts && detail::boundsCounts(main.policy.type)) {
    // The clamps' misses of cells never hit, bounded as their counts are (countBound) where the
    // bound is finite ("clamp" to [0, bound]: counts never fall, the lower bound never acts).
    const double bound = detail::countBound(main);
    if (!std::isinf(bound)) {
      p.policy.type = PolicyType::kClamp;
      p.policy.clamp_min = 0.0;
      p.policy.clamp_max = bound;
    }
  }
  return p;
}

detail::ReflectionBasis WaveletMap::Impl::currentBasis() const {
  return {params.policy.type, params.sensor.odd_occ, params.sensor.odd_emp, params.initValue()};
}

void WaveletMap::Impl::restartReflection(bool fresh) {
  for (auto& kv : blocks) kv.second.hits.reset();
  hits_layer.reset();
  misses_layer.reset();
  reflection_basis = currentBasis();
  if (!params.reflection) {
    reflection_mode = ReflectionMode::kOff;
    return;
  }
  const PolicyType type = params.policy.type;
  if (type == PolicyType::kForget) {
    if (!fresh) {
      reflection_mode = ReflectionMode::kLayers;
    } else {
      reflection_mode = params.policy.init == InitValue::kUnknown ? ReflectionMode::kDerived
                                                                  : ReflectionMode::kPrior;
    }
  } else if ((type == PolicyType::kNone || detail::boundsCounts(type)) && fresh) {
    reflection_mode = ReflectionMode::kDerived;
  } else {
    reflection_mode = ReflectionMode::kCounts;
  }
  const auto make = [this](std::unique_ptr<WaveletMap>* layer, bool hits) {
    layer->reset(new WaveletMap(layerParams(params, hits, reflection_mode), LayerTag{}));
  };
  if (reflection_mode == ReflectionMode::kLayers) make(&hits_layer, true);
  const bool layer_misses =
      type != PolicyType::kMax &&
      (reflection_mode == ReflectionMode::kLayers || reflection_mode == ReflectionMode::kCounts);
  if (layer_misses) make(&misses_layer, false);
}

void WaveletMap::Impl::settlePairs(const MapParams& next) {
  if (!params.reflection || !detail::boundsCounts(params.policy.type)) return;
  // A cell above a lowered clamp_max falls to it at its next miss: its reference is put where one
  // miss takes it there, so that the miss counts one.
  const double top = next.policy.type == PolicyType::kClampLower
                         ? std::numeric_limits<double>::infinity()
                         : next.policy.clamp_max - next.sensor.odd_emp;
  const bool drop = reflection_mode != ReflectionMode::kCounts;
  for (auto& kv : blocks) {
    Block& b = kv.second;
    if (!b.hits || b.hits->pairs.empty()) continue;
    detail::BlockCellReader occupancy(*this, b);
    for (detail::HitPair& e : b.hits->pairs.entries) {
      if (!e.live()) continue;
      const double l = occupancy.average(e.code);
      const detail::PairCounts now = detail::pairNow(e, l, params);
      if (now.at_bound && drop) {  // as the walk would have dropped it
        b.hits->pairs.drop(&e);
        continue;
      }
      e.h = static_cast<float>(now.h);
      e.m = static_cast<float>(now.m);
      e.l = static_cast<float>(std::min(l, top));
    }
  }
}

void WaveletMap::Impl::configureReflection() {
  if (!params.reflection) return;
  if (currentBasis() != reflection_basis) {
    restartReflection(blocks.empty());
    return;
  }
  for (std::unique_ptr<WaveletMap>* layer : {&hits_layer, &misses_layer}) {
    if (!*layer) continue;
    Impl& impl = *(*layer)->impl_;
    impl.flushAll();  // pending counts stand for the old factor
    impl.params = layerParams(params, layer == &hits_layer, reflection_mode);
    impl.configure();
  }
}

void WaveletMap::Impl::adoptReflection(ReflectionMode mode, const detail::ReflectionBasis& basis,
                                       std::unique_ptr<WaveletMap> hits,
                                       std::unique_ptr<WaveletMap> misses) {
  const bool needs_misses = params.policy.type != PolicyType::kMax &&
                            (mode == ReflectionMode::kLayers || mode == ReflectionMode::kCounts);
  const bool complete = (mode != ReflectionMode::kLayers || hits != nullptr) &&
                        (needs_misses ? misses != nullptr : misses == nullptr);
  if (mode == ReflectionMode::kOff || basis != currentBasis() || !complete) {
    restartReflection(blocks.empty());
    return;
  }
  reflection_mode = mode;
  hits_layer = std::move(hits);
  misses_layer = std::move(misses);
  // Read with the layer parameters of kLayers: those of this mode from here on.
  for (std::unique_ptr<WaveletMap>* layer : {&hits_layer, &misses_layer}) {
    if (!*layer) continue;
    Impl& impl = *(*layer)->impl_;
    impl.params = layerParams(params, layer == &hits_layer, reflection_mode);
    impl.configure();
  }
}

namespace {

const WaveletMap::Impl& requireReflection(const WaveletMap::Impl& impl) {
  if (impl.reflection_mode == ReflectionMode::kOff) {
    throw std::logic_error("this map keeps no reflection map (MapParams::reflection)");
  }
  return impl;
}

// p of one cell or raster cell from its mean hits and misses (NaN: nothing observed).
float probability(double h, double m) {
  const double total = h + m;  // float round-off may leave a count a hair below 0
  if (!(total > 0.0)) return h > 0.0 ? 1.0f : 0.0f;
  return static_cast<float>(std::fmin(1.0, std::fmax(0.0, h / total)));
}

// The hits of the cell of an entry (under "forget", read with its occupancy).
double hitsOf(const WaveletMap::Impl&, const detail::HitCount& e, detail::BlockCellReader*) {
  return static_cast<double>(e.n);
}
double hitsOf(const WaveletMap::Impl& impl, const detail::HitRatio& e,
              detail::BlockCellReader* occupancy) {
  return impl.reflection_basis.hitsFromRatio(occupancy->average(e.code), e.q);
}

// Per scale-s cell of a window, row-major: the mean hits of its cells, and under the clamps the
// mean of what the entries' misses add to those the cells read as never hit; at scale 0, the
// misses of a cell with a pair (`paired`), read from it alone: `l / odd_emp + dm` would add and
// take away the misses the cell's log-odds stands for, which at large log-odds (a loaded file)
// swamps its counts in the float log-odds of the read-out and not in the point query's double.
struct HitSums {
  std::vector<double> h, dm, pair_m;
  std::vector<std::uint8_t> paired;
};

// Adds the hits of every hit cell of block `b` (origin cell x0, y0) in `window` (scale-s cells)
// to `sums`.
template <typename Entry>
void addHits(const WaveletMap::Impl& impl, const Block& b, const detail::CellRuns<Entry>& runs,
             std::int64_t x0, std::int64_t y0, int s, const CellBox& window, HitSums* sums) {
  detail::BlockCellReader occupancy(impl, b);
  for (const Entry& e : runs.entries) {
    if (!e.live()) continue;
    std::uint32_t lx, ly;
    detail::mortonCell(e.code, &lx, &ly);
    const std::int64_t ix = x0 + lx, iy = y0 + ly;
    const std::int64_t rx = ix >> s, ry = iy >> s;
    if (rx < window.min_x || rx >= window.max_x || ry < window.min_y || ry >= window.max_y)
      continue;
    const auto k =
        static_cast<std::size_t>((ry - window.min_y) * window.width() + (rx - window.min_x));
    if constexpr (std::is_same_v<Entry, detail::HitPair>) {
      const double l = occupancy.average(e.code);
      const detail::PairCounts now = detail::pairNow(e, l, impl.params);
      sums->h[k] += now.h;
      sums->dm[k] += now.m - impl.unhitMisses(ix, iy, l);
      if (s == 0) {
        sums->pair_m[k] = now.m;
        sums->paired[k] = 1;
      }
    } else {
      sums->h[k] += hitsOf(impl, e, &occupancy);
    }
  }
}

// The hit sums of every scale-s cell of `window`, as means over its cells.
HitSums meanHits(const WaveletMap::Impl& impl, int s, const CellBox& window) {
  const auto n = static_cast<std::size_t>(window.width() * window.height());
  HitSums sums{std::vector<double>(n, 0.0), std::vector<double>(n, 0.0),
               std::vector<double>(s == 0 ? n : 0, 0.0),
               std::vector<std::uint8_t>(s == 0 ? n : 0, 0)};
  const int L = impl.levels;
  const std::int64_t span = std::int64_t{1} << (L - s);  // scale-s cells per block side
  for (const auto& kv : impl.blocks) {
    const Block& b = kv.second;
    if (!b.hits || b.hits->empty()) continue;
    const std::int64_t bx = detail::blockKeyX(kv.first), by = detail::blockKeyY(kv.first);
    if ((bx + 1) * span <= window.min_x || bx * span >= window.max_x ||
        (by + 1) * span <= window.min_y || by * span >= window.max_y) {
      continue;
    }
    const std::int64_t x0 = detail::scaleUp(bx, L), y0 = detail::scaleUp(by, L);
    addHits(impl, b, b.hits->counts, x0, y0, s, window, &sums);
    addHits(impl, b, b.hits->ratios, x0, y0, s, window, &sums);
    addHits(impl, b, b.hits->pairs, x0, y0, s, window, &sums);
  }
  const double cells = std::ldexp(1.0, 2 * s);
  for (double& v : sums.h) v /= cells;
  for (double& v : sums.dm) v /= cells;
  return sums;
}

// p of an observed cell or raster cell of mean log-odds `l` (the hits layer's mean under
// kLayers), mean hits `h` (kDerived, kCounts), mean value of the misses layer `m` and, under the
// clamps, the entries' mean misses over those of never hit cells `dm`.
float fromCounts(const WaveletMap::Impl& impl, double l, double h, double m, double dm) {
  const bool pairs = detail::boundsCounts(impl.reflection_basis.type);
  switch (impl.reflection_mode) {
    case ReflectionMode::kDerived:
      if (pairs) return probability(h, impl.reflection_basis.missesOfUnhit(l) + dm);
      return probability(h, impl.reflection_basis.misses(l, h));
    case ReflectionMode::kPrior: {
      const double prior_h = impl.reflection_basis.hitsFromRatio(l, 0.0f);  // h + m = 1
      return probability(prior_h, 1.0 - prior_h);
    }
    case ReflectionMode::kCounts:
      return probability(h, m + (pairs ? dm : 0.0));
    case ReflectionMode::kLayers:
      return probability(l, m);
    case ReflectionMode::kOff:
      break;
  }
  return std::numeric_limits<float>::quiet_NaN();
}

}  // namespace

ReflectionRaster WaveletMap::exportReflection(int scale, const CellBox& window) const {
  const Impl& impl = requireReflection(*impl_);
  const ReflectionMode mode = impl.reflection_mode;
  // Every count shares the main map's classification, so the knowledge is the main map's, or,
  // since a restart, that of the layers (the hits layer's, or the misses layer's under kCounts).
  const Raster main = mode == ReflectionMode::kLayers
                          ? impl.hits_layer->exportScale(scale, window, Aggregation::kMean)
                          : exportScale(scale, window, Aggregation::kMean);
  Raster misses;
  if (impl.misses_layer) misses = impl.misses_layer->exportScale(scale, window, Aggregation::kMean);
  const std::vector<std::uint8_t>& known =
      mode == ReflectionMode::kCounts && impl.misses_layer ? misses.known : main.known;
  ReflectionRaster r;
  r.scale = main.scale;
  r.cell_size = main.cell_size;
  r.box = main.box;
  r.p.assign(main.log_odds.size(), std::numeric_limits<float>::quiet_NaN());
  HitSums hits;
  if (mode == ReflectionMode::kDerived || mode == ReflectionMode::kCounts) {
    hits = meanHits(impl, r.scale, r.box);
  }
  for (std::size_t i = 0; i < r.p.size(); ++i) {
    if (known[i] == 0) continue;
    if (!hits.paired.empty() && hits.paired[i]) {  // scale 0: a cell with a pair
      r.p[i] = probability(hits.h[i], hits.pair_m[i]);
      continue;
    }
    r.p[i] = fromCounts(impl, main.log_odds[i], hits.h.empty() ? 0.0 : hits.h[i],
                        impl.misses_layer ? misses.log_odds[i] : 0.0,
                        hits.dm.empty() ? 0.0 : hits.dm[i]);
  }
  return r;
}

float WaveletMap::reflection(const CellIndex& cell) const {
  const Impl& impl = requireReflection(*impl_);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const double m = impl.misses_layer ? impl.misses_layer->value(cell) : 0.0;
  if (impl.reflection_mode == ReflectionMode::kLayers) {
    const WaveletMap& hits = *impl.hits_layer;
    return hits.isObserved(cell) ? fromCounts(impl, hits.value(cell), 0.0, m, 0.0) : nan;
  }
  // One read of the cell's occupancy: its knowledge (or the misses layer's, since a restart under
  // kCounts) and its log-odds, from which the hits of a ratio are read too.
  if (!inExtent(cell.x, cell.y)) return nan;
  const Impl::SlotRead occupancy = impl.read(0, cell.x, cell.y);
  const bool counted_misses = impl.reflection_mode == ReflectionMode::kCounts && impl.misses_layer;
  if (!(counted_misses ? impl.misses_layer->isObserved(cell) : occupancy.known_all)) return nan;
  const double l = occupancy.average;
  const int L = impl.levels;
  const std::int64_t mask = (std::int64_t{1} << L) - 1;
  double h = 0.0, dm = 0.0;
  const Block* b = impl.findBlock(detail::floorShift(cell.x, L), detail::floorShift(cell.y, L));
  if (b != nullptr && b->hits) {
    const auto code = detail::mortonCode(static_cast<std::uint32_t>(cell.x & mask),
                                         static_cast<std::uint32_t>(cell.y & mask));
    if (const detail::HitCount* e = b->hits->counts.find(code); e != nullptr && e->live()) {
      h = static_cast<double>(e->n);
    }
    if (const detail::HitRatio* e = b->hits->ratios.find(code); e != nullptr && e->live()) {
      h = impl.reflection_basis.hitsFromRatio(l, e->q);
    }
    if (const detail::HitPair* e = b->hits->pairs.find(code); e != nullptr && e->live()) {
      const detail::PairCounts now = detail::pairNow(*e, l, impl.params);
      return probability(now.h, now.m);  // its own misses (HitSums)
    }
  }
  return fromCounts(impl, l, h, m, dm);
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
