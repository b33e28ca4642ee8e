// WaveletMap::Impl, the map's storage (map_impl.h): derived constants of the parameters, node
// creation and deletion, flushing every lazy tag, block lookup and creation.
#include <algorithm>
#include <cmath>

#include "map_impl.h"

namespace wavog {

using detail::Block;
using detail::Node;

namespace {
// Spare groups a new block takes from the pool's own free list.
constexpr std::size_t kLentGroups = 64;
}  // namespace

WaveletMap::Impl::Impl(const MapParams& p) : params(p) {
  throwIfInvalid(p);
  levels = p.grid.block_levels;
  configure();
}

void WaveletMap::Impl::configure() {
  init = params.initValue();
  a = params.policy.type == PolicyType::kForget ? 1.0 - params.policy.gamma : 1.0;
  pow_a[0] = 1.0;
  for (std::size_t k = 1; k < pow_a.size(); ++k) pow_a[k] = pow_a[k - 1] * a;
  // tau = 0 still drops details below float round-off of the log-odds scale.
  constexpr double kRoundOff = 1e-6;
  prune_threshold = std::max(params.prune_threshold, kRoundOff);
  // Section 6.5: all values stay in [odd_emp, odd_occ], so |d| <= 2R; after K* pending steps
  // every detail of the subtree is below the pruning threshold and the subtree can go.
  k_star = 256;
  if (params.policy.type == PolicyType::kForget) {
    const double r = params.sensor.odd_occ - params.sensor.odd_emp;
    if (a <= 0.0) {
      k_star = 1;
    } else if (a < 1.0) {
      const double k = std::ceil(std::log(prune_threshold / (2.0 * r)) / std::log(a));
      if (k < 255.0) k_star = std::max(1, static_cast<int>(k));
    }
  }
}

void WaveletMap::Impl::freeSubtree(detail::NodeStore& store, Node& n) {
  if (n.children == 0) return;
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
    pool.lend(kLentGroups, &res.first->second.spare);
  }
  return res.first->second;
}

void WaveletMap::Impl::dropIfEmpty(std::int64_t bx, std::int64_t by) {
  auto it = blocks.find(detail::blockKey(bx, by));
  if (it == blocks.end()) return;
  const Block& b = it->second;
  if (!b.has_root && !b.known_any && b.s == init) eraseBlock(it->first);
}

void WaveletMap::Impl::eraseBlock(std::uint64_t key) {
  auto it = blocks.find(key);
  if (it == blocks.end()) return;
  for (std::uint32_t g : it->second.spare) pool.recycle(g);
  blocks.erase(it);
}

}  // namespace wavog
