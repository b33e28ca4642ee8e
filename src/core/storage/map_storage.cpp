// WaveletMap::Impl, the map's storage (map_impl.h): derived constants of the parameters, node
// creation and deletion, flushing every lazy tag, block lookup and creation.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <type_traits>

#include "storage/map_impl.h"

namespace wavog {

using detail::Block;
using detail::Node;

namespace {
// Spare groups and tiles a new block takes from the pools' own free lists.
constexpr std::size_t kLentGroups = 64, kLentTiles = 16;
}  // namespace

WaveletMap::Impl::Impl(const MapParams& p, bool validate) : params(p) {
  if (validate) throwIfInvalid(p);
  levels = p.grid.block_levels;
  tile_level = detail::tileLevel(levels);
  configure();
  restartReflection(true);
}

void WaveletMap::Impl::configure() {
  const PolicyType type = params.policy.type;
  setTileKind(type == PolicyType::kNone || type == PolicyType::kClampLower ||
              type == PolicyType::kClampUpper);
  init = params.initValue();
  const bool forget = params.policy.type == PolicyType::kForget;
  a = forget ? 1.0 - params.policy.gamma : 1.0;
  // tau = 0 still drops details below float round-off of the log-odds scale.
  constexpr double kRoundOff = 1e-6;
  prune_threshold = std::max(params.prune_threshold, kRoundOff);
  // Section 6.5: all values stay between odd_emp and odd_occ (R = |odd_occ - odd_emp|; a
  // reflection layer's odd values are 0 and 1 either way round), so |d| <= 2R; once the pending
  // multiplier is below tau / 2R every detail of the subtree is below the pruning threshold and
  // the subtree can go.
  const double range = std::fabs(params.sensor.odd_occ - params.sensor.odd_emp);
  const double halvings = std::max(0.0, std::log2(2.0 * range / prune_threshold));
  half_life = forget && params.policy.forget_half_life > 0.0;
  if (half_life) {
    // The finest unit 2^-e for which the negligible multiplier of the widest odd range (100:
    // odd_occ <= 50, odd_emp >= -50) still fits a 16-bit count (2^-11 at tau = 0) ...
    constexpr double kMaxCount = 65535.0, kWidestRange = 100.0;
    const double widest = std::log2(2.0 * kWidestRange / prune_threshold);
    const int e_count = std::min(16, static_cast<int>(std::floor(std::log2(kMaxCount / widest))));
    // ... or finer, for long half-lives: a scan of kResolvedPeriod counts at least kResolvedUnits
    // units, so that its rate is within 1 / (2 kResolvedUnits) of the exact one (with 2^-11 a
    // half-life above 2^11 periods / 2 rounded every scan to 0 units: issue 28). A scan of up to
    // 65535 units still fits one tag (12.8 s / forget_half_life halvings); a longer one is
    // applied eagerly (forgetSubtree). Both depend on tau and the half-life only, so a map and
    // its reflection layers share the unit (and so each scan's factor).
    const double resolved =
        std::log2(kResolvedUnits * params.policy.forget_half_life / kResolvedPeriod);
    const int e = std::max(e_count, static_cast<int>(std::ceil(resolved)));
    unit_log2 = std::ldexp(1.0, -e);
    k_cap = 65535;
    k_star = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::ceil(halvings / unit_log2)));
    for (std::size_t j = 0; j < mult_lo.size(); ++j) {
      mult_lo[j] = std::exp2(-static_cast<double>(j) * unit_log2);
      mult_hi[j] = std::exp2(-static_cast<double>(256 * j) * unit_log2);
    }
    return;
  }
  unit_log2 = 0.0;
  k_cap = 255;
  mult_lo[0] = 1.0;
  for (std::size_t k = 1; k < mult_lo.size(); ++k) mult_lo[k] = mult_lo[k - 1] * a;
  mult_hi.fill(0.0);
  mult_hi[0] = 1.0;  // counts stay <= 255: multiplier(k) is a^k as a product of k factors
  k_star = 256;
  if (forget) {
    if (a <= 0.0) {
      k_star = 1;
    } else if (a < 1.0) {
      const double k = std::ceil(std::log(prune_threshold / (2.0 * range)) / std::log(a));
      if (k < 255.0) k_star = static_cast<std::uint64_t>(std::max(1, static_cast<int>(k)));
    }
  }
}

std::uint64_t WaveletMap::Impl::scanUnits(double period) const {
  if (!half_life) return 1;
  const double exponent = std::isfinite(period) && period > 0.0
                              ? period / params.policy.forget_half_life
                              : -std::log2(1.0 - params.policy.gamma);  // +inf for gamma 1
  const double units = std::round(exponent / unit_log2);
  if (units >= static_cast<double>(k_star)) return k_star;
  // At least one unit: a scan shorter than half a unit still forgets (g > 0), so it still learns
  // and never adds an end-point of weight 0 (NDT) or a hit ratio 0 / 0 (reflection).
  return units < 1.0 ? 1 : static_cast<std::uint64_t>(units);
}

void WaveletMap::Impl::freeSubtree(detail::NodeStore& store, Node& n) {
  if (n.children == 0) return;
  if (hasTile(n)) {
    store.releaseTile(n.children);
    n.children = 0;
    n.child_mask = 0;
    return;
  }
  for (int q = 0; q < 4; ++q) {
    if (hasChild(n, q)) {
      freeSubtree(store, child(n, q));
      store.nodeRemoved();
    }
  }
  store.release(n.children);
  n.children = 0;
  n.child_mask = 0;
}

void WaveletMap::Impl::removeChild(detail::NodeStore& store, Node& n, int q) {
  freeSubtree(store, child(n, q));
  store.nodeRemoved();
  n.child_mask = static_cast<std::uint8_t>(n.child_mask & ~(1u << q));
  if (n.child_mask == 0) {
    store.release(n.children);
    n.children = 0;
  }
}

namespace {
// Calls f(n) for every tile node of the subtree of n.
template <typename F>
void forEachTileNode(WaveletMap::Impl& impl, Node& n, F& f) {
  if (WaveletMap::Impl::hasTile(n)) {
    f(n);
    return;
  }
  if (n.children == 0) return;
  for (int q = 0; q < 4; ++q) {
    if (impl.hasChild(n, q)) forEachTileNode(impl, impl.child(n, q), f);
  }
}

// Copies the tile of node n from pool `from` into a new one of pool `to`.
template <typename From, typename To>
void moveTile(Node& n, detail::ChunkPool<From>& from, detail::ChunkPool<To>& to) {
  using T = std::remove_reference_t<decltype(To{}.v[0])>;
  const std::uint32_t i = to.allocate(false);
  const From& a = from.group(n.children);
  To& b = to.group(i);
  for (std::size_t c = 0; c < 64; ++c) b.v[c] = detail::storedValue<T>(a.v[c]);
  b.known = a.known;
  b.base = a.base;
  from.release(n.children);
  n.children = i;
}
}  // namespace

void WaveletMap::Impl::setTileKind(bool wide) {
  if (wide == tiles.wide()) return;
  for (auto& kv : blocks) {
    tiles.recycleSpares(&kv.second.spare.tiles);
    for (detail::Spares& part : kv.second.part_spare) tiles.recycleSpares(&part.tiles);
  }
  auto convert = [&](Node& n) {
    if (wide) {
      moveTile(n, tiles.narrow(), tiles.wideTiles());
    } else {
      moveTile(n, tiles.wideTiles(), tiles.narrow());
    }
  };
  for (auto& kv : blocks) {
    if (kv.second.has_root) forEachTileNode(*this, kv.second.root, convert);
  }
  tiles.setWide(wide);
}

namespace {
void flushTree(WaveletMap::Impl& impl, Node& n) {
  impl.flush(n);
  if (n.children == 0) return;
  for (int q = 0; q < 4; ++q) {
    if (impl.hasChild(n, q)) flushTree(impl, impl.child(n, q));
  }
}
}  // namespace

void WaveletMap::Impl::flushAll() {
  for (auto& kv : blocks) {
    if (kv.second.has_root) flushTree(*this, kv.second.root);
  }
}

Block* WaveletMap::Impl::findBlock(std::int64_t bx, std::int64_t by) {
  auto it = blocks.find(detail::blockKey(bx, by));
  return it == blocks.end() ? nullptr : &it->second;
}

const Block* WaveletMap::Impl::findBlock(std::int64_t bx, std::int64_t by) const {
  auto it = blocks.find(detail::blockKey(bx, by));
  return it == blocks.end() ? nullptr : &it->second;
}

Block& WaveletMap::Impl::getOrCreateBlock(std::int64_t bx, std::int64_t by) {
  auto res = blocks.try_emplace(detail::blockKey(bx, by));
  if (res.second) {
    res.first->second.s = init;
    // Groups of erased blocks go to new ones (integrations take only their block's spares).
    pool.lend(kLentGroups, &res.first->second.spare.groups);
    tiles.lend(kLentTiles, &res.first->second.spare.tiles);
  }
  return res.first->second;
}

void WaveletMap::Impl::dropIfEmpty(std::int64_t bx, std::int64_t by) {
  auto it = blocks.find(detail::blockKey(bx, by));
  if (it == blocks.end()) return;
  const Block& b = it->second;
  if (!b.has_root && !b.known_any && b.s == init && !(b.ndt && !b.ndt->empty())) {
    eraseBlock(it->first);
  }
}

void WaveletMap::Impl::eraseBlock(std::uint64_t key) {
  auto it = blocks.find(key);
  if (it == blocks.end()) return;
  const auto recycle = [this](detail::Spares* sp) {
    pool.recycleSpares(&sp->groups);
    tiles.recycleSpares(&sp->tiles);
  };
  recycle(&it->second.spare);
  for (detail::Spares& part : it->second.part_spare) recycle(&part);
  blocks.erase(it);
}

}  // namespace wavog
