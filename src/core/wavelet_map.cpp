// Storage side of WaveletMap: pool, blocks, lazy tags, point queries, region clearing, stats.
#include "wavog_mapping/core/wavelet_map.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "map_impl.h"
#include "wavog_mapping/core/haar.h"

namespace wavog {

using detail::Block;
using detail::Node;

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

void WaveletMap::Impl::freeSubtree(Node& n) {
  if (n.children == 0) return;
  for (int q = 0; q < 4; ++q) {
    if (hasChild(n, q)) {
      freeSubtree(child(n, q));
      --nodes;
    }
  }
  pool.release(n.children);
  n.children = 0;
  n.child_mask = 0;
}

void WaveletMap::Impl::removeChild(Node& n, int q) {
  freeSubtree(child(n, q));
  --nodes;
  n.child_mask = static_cast<std::uint8_t>(n.child_mask & ~(1u << q));
  if (n.child_mask == 0) {
    pool.release(n.children);
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
  if (res.second) res.first->second.s = init;
  return res.first->second;
}

void WaveletMap::Impl::dropIfEmpty(std::int64_t bx, std::int64_t by) {
  auto it = blocks.find(detail::blockKey(bx, by));
  if (it == blocks.end()) return;
  const Block& b = it->second;
  if (!b.has_root && !b.known_any && b.s == init) blocks.erase(it);
}

// ---------------------------------------------------------------------------------------------

WaveletMap::WaveletMap(const MapParams& params) : impl_(std::make_unique<Impl>(params)) {}
WaveletMap::~WaveletMap() = default;
WaveletMap::WaveletMap(WaveletMap&&) noexcept = default;
WaveletMap& WaveletMap::operator=(WaveletMap&&) noexcept = default;

const MapParams& WaveletMap::params() const { return impl_->params; }
double WaveletMap::resolution() const { return impl_->params.grid.resolution; }

CellIndex WaveletMap::cellAt(double x, double y) const {
  const double r = impl_->params.grid.resolution;
  return {static_cast<std::int64_t>(std::floor(x / r)),
          static_cast<std::int64_t>(std::floor(y / r))};
}

namespace {
// Walks from the block root towards `cell`, reconstructing averages (lazy tags applied on the
// way, nothing written). Returns the cell's value and whether it was observed.
std::pair<float, bool> lookup(const WaveletMap::Impl& impl, const CellIndex& cell) {
  const int levels = impl.levels;
  const Block* b =
      impl.findBlock(detail::floorShift(cell.x, levels), detail::floorShift(cell.y, levels));
  if (b == nullptr) return {static_cast<float>(impl.init), false};
  double s = b->s;
  if (!b->has_root) return {static_cast<float>(b->known_all ? s : impl.init), b->known_all};
  const Node* n = &b->root;
  double mult = 1.0;
  for (int l = levels; l >= 1; --l) {
    mult *= impl.pow_a[n->k];
    const int q = static_cast<int>(((cell.x >> (l - 1)) & 1) | (((cell.y >> (l - 1)) & 1) << 1));
    const double d[3] = {n->d[0] * mult, n->d[1] * mult, n->d[2] * mult};
    s = haar::backwardChild(s, d, q);
    if (l == 1 || !impl.hasChild(*n, q)) {
      // A never-observed cell holds the prior exactly; reading it back through the details
      // would only add their float round-off.
      const bool known = ((n->known_all >> q) & 1u) != 0;
      return {static_cast<float>(known ? s : impl.init), known};
    }
    n = &impl.child(*n, q);
  }
  return {static_cast<float>(s), false};
}
}  // namespace

float WaveletMap::value(const CellIndex& cell) const { return lookup(*impl_, cell).first; }
bool WaveletMap::isObserved(const CellIndex& cell) const { return lookup(*impl_, cell).second; }

void WaveletMap::reset() {
  impl_->blocks.clear();
  impl_->pool.clear();
  impl_->nodes = 0;
}

void WaveletMap::setPolicy(const PolicyParams& policy, const SensorModelParams& sensor) {
  MapParams p = impl_->params;
  p.policy = policy;
  p.sensor = sensor;
  throwIfInvalid(p);
  impl_->flushAll();  // pending counts stand for a^k with the old a (ALGORITHM.md F5)
  const double old_init = impl_->init;
  impl_->params = p;
  impl_->configure();
  // Never-observed space follows the new prior: uniform unobserved blocks are the only place it
  // is stored without a cell of its own (missing blocks read as the prior already).
  if (impl_->init != old_init) {
    for (auto& kv : impl_->blocks) {
      Block& b = kv.second;
      if (!b.has_root && !b.known_any) b.s = impl_->init;
    }
  }
}

// ---- Region clearing --------------------------------------------------------------------------

namespace {

struct ClearBox {
  std::int64_t x0, y0, x1, y1;  // inclusive finest-cell bounds
};

// Sets every finest cell of the box inside node `n` (level l, origin ix0/iy0, average s) back to
// the prior and unobserved. Returns the change of n's average.
double clearNode(WaveletMap::Impl& impl, Node& n, int l, std::int64_t ix0, std::int64_t iy0,
                 double s, const ClearBox& box) {
  impl.flush(n);
  const auto c = haar::backward(s, n.d);
  std::array<double, 4> delta{};
  const std::int64_t half = std::int64_t{1} << (l - 1);
  for (int q = 0; q < 4; ++q) {
    const std::int64_t cx = ix0 + ((q & 1) ? half : 0);
    const std::int64_t cy = iy0 + ((q & 2) ? half : 0);
    const std::int64_t ex = cx + half - 1, ey = cy + half - 1;
    if (ex < box.x0 || cx > box.x1 || ey < box.y0 || cy > box.y1) continue;
    const std::uint8_t bit = static_cast<std::uint8_t>(1u << q);
    const bool inside = cx >= box.x0 && ex <= box.x1 && cy >= box.y0 && ey <= box.y1;
    if (inside || l == 1) {
      if (l > 1 && impl.hasChild(n, q)) impl.removeChild(n, q);
      delta[static_cast<std::size_t>(q)] = impl.init - c[static_cast<std::size_t>(q)];
      detail::setBit(&n.known_all, bit, false);
      detail::setBit(&n.known_any, bit, false);
      continue;
    }
    const bool existed = impl.hasChild(n, q);
    Node tmp = WaveletMap::Impl::uniformSlot((n.known_all & bit) != 0, (n.known_any & bit) != 0);
    Node& m = existed ? impl.child(n, q) : tmp;
    delta[static_cast<std::size_t>(q)] =
        clearNode(impl, m, l - 1, cx, cy, c[static_cast<std::size_t>(q)], box);
    bool all = false, any = false;
    impl.settleSlot(
        m, existed, &all, &any, [&](const Node& kept) { impl.installChild(n, q, kept); },
        [&]() { impl.removeChild(n, q); });
    detail::setBit(&n.known_all, bit, all);
    detail::setBit(&n.known_any, bit, any);
  }
  haar::Details<double> dd;
  const double ds = haar::forward(delta, &dd);
  for (int i = 0; i < 3; ++i) n.d[i] = static_cast<float>(n.d[i] + dd[static_cast<std::size_t>(i)]);
  return ds;
}

}  // namespace

void WaveletMap::clearBox(double min_x, double min_y, double max_x, double max_y) {
  if (!(min_x <= max_x && min_y <= max_y)) return;  // also rejects NaN
  Impl& impl = *impl_;
  const double r = impl.params.grid.resolution;
  // Cells whose centre (i + 0.5) r lies in [min, max].
  const ClearBox box{static_cast<std::int64_t>(std::ceil(min_x / r - 0.5)),
                     static_cast<std::int64_t>(std::ceil(min_y / r - 0.5)),
                     static_cast<std::int64_t>(std::floor(max_x / r - 0.5)),
                     static_cast<std::int64_t>(std::floor(max_y / r - 0.5))};
  if (box.x1 < box.x0 || box.y1 < box.y0) return;
  const int L = impl.levels;
  const std::int64_t size = std::int64_t{1} << L;
  std::vector<std::uint64_t> keys;
  for (const auto& kv : impl.blocks) {
    const std::int64_t bx = detail::blockKeyX(kv.first), by = detail::blockKeyY(kv.first);
    const std::int64_t x0 = bx * size, y0 = by * size;
    if (x0 + size - 1 < box.x0 || x0 > box.x1 || y0 + size - 1 < box.y0 || y0 > box.y1) continue;
    keys.push_back(kv.first);
  }
  for (std::uint64_t key : keys) {
    Block& b = impl.blocks.at(key);
    const std::int64_t bx = detail::blockKeyX(key), by = detail::blockKeyY(key);
    const std::int64_t x0 = bx * size, y0 = by * size;
    const bool inside =
        x0 >= box.x0 && x0 + size - 1 <= box.x1 && y0 >= box.y0 && y0 + size - 1 <= box.y1;
    if (inside) {
      if (b.has_root) impl.removeRoot(&b);
      impl.blocks.erase(key);
      continue;
    }
    Node tmp = WaveletMap::Impl::uniformSlot(b.known_all, b.known_any);
    Node& m = b.has_root ? b.root : tmp;
    b.s += clearNode(impl, m, L, x0, y0, b.s, box);
    impl.settleSlot(
        m, b.has_root, &b.known_all, &b.known_any,
        [&](const Node& kept) { impl.installRoot(&b, kept); }, [&]() { impl.removeRoot(&b); });
    impl.dropIfEmpty(bx, by);
  }
}

// ---- Stats ------------------------------------------------------------------------------------

namespace {
std::uint64_t countObserved(const WaveletMap::Impl& impl, const Node& n, int l) {
  std::uint64_t count = 0;
  for (int q = 0; q < 4; ++q) {
    if (l > 1 && impl.hasChild(n, q)) {
      count += countObserved(impl, impl.child(n, q), l - 1);
    } else if ((n.known_all >> q) & 1u) {
      count += std::uint64_t{1} << (2 * (l - 1));
    }
  }
  return count;
}
}  // namespace

MapStats WaveletMap::stats(bool count_observed) const {
  const Impl& impl = *impl_;
  MapStats st;
  st.blocks = impl.blocks.size();
  st.nodes = impl.nodes;
  // Hash: one heap node per block (key, Block, next pointer, cached hash) plus the bucket array.
  const std::size_t per_block = sizeof(std::uint64_t) + sizeof(Block) + 2 * sizeof(void*);
  const std::size_t rest =
      impl.blocks.size() * per_block + impl.blocks.bucket_count() * sizeof(void*) + sizeof(Impl);
  st.bytes = impl.pool.bytes() + rest;
  st.bytes_reserved = impl.pool.bytesReserved() + rest;
  st.nodes_visited_last = impl.nodes_visited_last;
  if (count_observed) {
    for (const auto& kv : impl.blocks) {
      const Block& b = kv.second;
      if (b.has_root) {
        st.observed_cells += countObserved(impl, b.root, impl.levels);
      } else if (b.known_all) {
        st.observed_cells += std::uint64_t{1} << (2 * impl.levels);
      }
    }
  }
  return st;
}

}  // namespace wavog
