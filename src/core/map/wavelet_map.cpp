// WaveletMap's life cycle and point queries: construction, parameters, policy changes, reset, and
// the value and knowledge of one finest cell. Integration: integrate.cpp; read-out: readout.cpp;
// region clearing: clear_box.cpp; files: map_io.cpp; figures: map_stats.cpp.
#include "wavog_mapping/core/wavelet_map.h"

#include <cmath>
#include <utility>

#include "storage/map_impl.h"
#include "wavog_mapping/core/haar.h"

namespace wavog {

using detail::Block;
using detail::Node;

WaveletMap::WaveletMap(const MapParams& params) : impl_(std::make_unique<Impl>(params)) {}
WaveletMap::WaveletMap(const MapParams& params, LayerTag)
    : impl_(std::make_unique<Impl>(params, false)) {}
WaveletMap::~WaveletMap() = default;
WaveletMap::WaveletMap(WaveletMap&&) noexcept = default;
WaveletMap& WaveletMap::operator=(WaveletMap&&) noexcept = default;

const MapParams& WaveletMap::params() const { return impl_->params; }
double WaveletMap::resolution() const { return impl_->params.grid.resolution; }

double WaveletMap::forgetRate(double period) const {
  const Impl& impl = *impl_;
  if (impl.params.policy.type != PolicyType::kForget) return 0.0;
  if (!impl.half_life) return impl.params.policy.gamma;
  return 1.0 - impl.scanFactor(impl.scanUnits(period));
}

double WaveletMap::forgetUnit() const { return impl_->unit_log2; }

CellIndex WaveletMap::cellAt(double x, double y) const {
  const double r = impl_->params.grid.resolution;
  return {clampedCellIndex(std::floor(x / r)), clampedCellIndex(std::floor(y / r))};
}

WaveletMap::Impl::SlotRead WaveletMap::Impl::read(int s, std::int64_t x, std::int64_t y) const {
  const std::int64_t fx = detail::scaleUp(x, s), fy = detail::scaleUp(y, s);
  const Block* b = findBlock(detail::floorShift(fx, levels), detail::floorShift(fy, levels));
  if (b == nullptr) return {init, false, false};
  double avg = b->s;
  if (!b->has_root) return {avg, b->known_all, b->known_any};
  const Node* n = &b->root;
  double mult = 1.0;
  for (int l = levels; l > s; --l) {
    mult *= multiplier(n->k);
    if (hasTile(*n)) {
      // The square of side 2^s holding the cell, within the tile (l = tile_level).
      const std::int64_t mask = (std::int64_t{1} << l) - 1;
      const std::uint64_t cells =
          detail::tileSquare(s, static_cast<unsigned>(fx & mask), static_cast<unsigned>(fy & mask));
      return withTile(*n, [&](const auto& t) {
        const std::uint64_t known = t.known & cells;
        return SlotRead{avg + mult * (detail::tileMean(t, cells) - t.base), known == cells,
                        known != 0};
      });
    }
    const int q = static_cast<int>(((fx >> (l - 1)) & 1) | (((fy >> (l - 1)) & 1) << 1));
    const double d[3] = {n->d[0] * mult, n->d[1] * mult, n->d[2] * mult};
    avg = haar::backwardChild(avg, d, q);
    if (l - 1 == s || !hasChild(*n, q)) {
      return {avg, ((n->known_all >> q) & 1u) != 0, ((n->known_any >> q) & 1u) != 0};
    }
    n = &child(*n, q);
  }
  return {avg, b->known_all, b->known_any};  // s = levels: the block itself
}

namespace {
// The value of one finest cell and whether it was observed. A never-observed cell holds the prior
// exactly; reading it back through the details would only add their float round-off.
std::pair<float, bool> lookup(const WaveletMap::Impl& impl, const CellIndex& cell) {
  // Outside the extent no block exists; a 32-bit block key of such a cell would alias one.
  if (!inExtent(cell.x, cell.y)) return {static_cast<float>(impl.init), false};
  const WaveletMap::Impl::SlotRead r = impl.read(0, cell.x, cell.y);
  return {static_cast<float>(r.known_all ? r.average : impl.init), r.known_all};
}
}  // namespace

float WaveletMap::value(const CellIndex& cell) const { return lookup(*impl_, cell).first; }
bool WaveletMap::isObserved(const CellIndex& cell) const { return lookup(*impl_, cell).second; }

void WaveletMap::reset() {
  impl_->blocks.clear();
  impl_->pool.clear();
  impl_->tiles.clear();
  impl_->counts = detail::StoreCounts{};
  impl_->restartReflection(true);  // the occupancy is empty again
}

void WaveletMap::setPolicy(const PolicyParams& policy, const SensorModelParams& sensor) {
  MapParams p = impl_->params;
  p.policy = policy;
  p.sensor = sensor;
  throwIfInvalid(p);
  impl_->flushAll();  // pending counts stand for a^k with the old a (ALGORITHM.md F5)
  const double old_init = impl_->init;
  impl_->settlePairs(p);
  impl_->params = p;
  impl_->configure();
  impl_->configureReflection();
  // Never-observed space follows the new prior: uniform unobserved blocks are the only place it
  // is stored without a cell of its own (missing blocks read as the prior already).
  if (impl_->init != old_init) {
    for (auto& kv : impl_->blocks) {
      Block& b = kv.second;
      if (!b.has_root && !b.known_any) b.s = impl_->init;
    }
  }
}

}  // namespace wavog
