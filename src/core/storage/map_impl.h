// WaveletMap::Impl, what a WaveletMap holds: its parameters and their derived constants, the node
// pool and the block hash, and the node operations every part of the map shares (create / free a
// child node, lazy forgetting tags). Storage: node_pool.h, block_hash.h; slots: map_slot.h.
// Not installed; included only by src/core/* and the core tests.
#ifndef WAVOG_MAPPING_SRC_CORE_STORAGE_MAP_IMPL_H_
#define WAVOG_MAPPING_SRC_CORE_STORAGE_MAP_IMPL_H_

#include <array>
#include <cmath>
#include <cstdint>
#include <memory>

#include "storage/block_hash.h"
#include "storage/cell_runs.h"
#include "storage/node_pool.h"
#include "wavog_mapping/core/params.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "update/worker_pool.h"

namespace wavog {
namespace detail {

/// A 4-bit knowledge mask with `bit` set or cleared.
inline std::uint8_t withBit(unsigned mask, unsigned bit, bool on) {
  return static_cast<std::uint8_t>((on ? (mask | bit) : (mask & ~bit)) & 0xFu);
}

}  // namespace detail

/// How a map keeps its reflection map (MapParams::reflection; reflection.cpp).
enum class ReflectionMode : std::uint8_t {
  kOff,      ///< no reflection map
  kDerived,  ///< "none", the clamps, or "forget" with the unknown prior: hits (the clamps: hits
             ///< and misses) per hit cell, the other misses from the occupancy (ReflectionBasis)
  kPrior,    ///< "forget" with the empty_bound prior: h from the occupancy alone, h + m = 1
  kCounts,   ///< "max", or "none" or the clamps restarted: hits (the clamps: hits and misses)
             ///< per hit cell, the other misses in misses_layer (none under "max")
  kLayers,   ///< "forget" restarted, or a version 2-3 file: hits and misses in two layers
};

/// Everything a WaveletMap holds. Members are public to the core's own translation units.
struct WaveletMap::Impl {
  /// `validate`: throw std::invalid_argument for invalid parameters (a reflection layer's are
  /// made by the core and are outside the users' ranges).
  explicit Impl(const MapParams& p, bool validate = true);

  MapParams params;
  int levels = 0;                 ///< block_levels
  double init = 0.0;              ///< prior log-odds of never-observed cells
  double a = 1.0;                 ///< 1 - gamma for "forget", else 1
  double prune_threshold = 1e-6;  ///< effective tau
  /// Pending forgetting (Node::k, ALGORITHM.md 6.3) counts units: one scan's a (a^k, k <= 255)
  /// without forget_half_life, else unit_log2 halvings each (2^(-k unit), k < 2^16), so that
  /// scans of different periods add their exponents exactly.
  bool half_life = false;
  double unit_log2 = 0.0;  ///< forget_half_life: halvings per unit
  /// forget_half_life: a scan of kResolvedPeriod s counts at least kResolvedUnits units (the unit
  /// is finer than the tau-based 2^-11 for half-lives above 0.8 s at tau = 0).
  static constexpr double kResolvedPeriod = 0.025, kResolvedUnits = 64.0;
  unsigned k_cap = 255;    ///< largest pending count a node holds (it is flushed beyond)
  /// Pending count at which a fully-E subtree is negligible. Without forget_half_life, and with
  /// the tau-based unit (half-lives up to 0.8 s at tau = 0), at most k_cap; with longer ones (finer units) it may
  /// exceed k_cap: a subtree is then dropped only by a scan that forgets this much at once.
  std::uint64_t k_star = 256;
  std::array<double, 256> mult_lo{};  ///< multiplier(k) for k < 256 (a^k: repeated products)
  std::array<double, 256> mult_hi{};  ///< multiplier(256 j)

  /// The true value of details stored under k pending units.
  double multiplier(unsigned k) const { return mult_hi[k >> 8] * mult_lo[k & 255u]; }
  /// Pending units of one scan of `period` s ("forget"; 1 without forget_half_life): its
  /// exponent rounded to the unit, at least 1 (a scan always forgets, so g > 0), at most k_star.
  /// May exceed k_cap (a long period, or gamma, under a fine unit; see forgetSubtree).
  std::uint64_t scanUnits(double period) const;
  /// The factor of `units` pending units: multiplier(units) up to k_cap, else 2^(-units unit).
  double scanFactor(std::uint64_t units) const {
    return units <= k_cap ? multiplier(static_cast<unsigned>(units))
                          : std::exp2(-static_cast<double>(units) * unit_log2);
  }
  /// The factor a pending count of k stands for, as saved (multiplier(k) = unitFactor()^k).
  double unitFactor() const { return half_life ? std::exp2(-unit_log2) : a; }

  detail::NodePool pool;
  detail::TilePool tiles;
  /// The level of the tile nodes (storage/tile.h): 3, or 2 in blocks of 2 levels.
  int tile_level = 3;
  detail::BlockMap blocks;
  /// Worker threads of parallel integrations (num_threads != 1), made on the first one.
  std::unique_ptr<detail::WorkerPool> workers;
  /// The reflection map (reflection.cpp): its mode, the policy, odd values and prior it has been
  /// built under since the map was empty or it restarted, and the layers of kCounts and kLayers
  /// (more maps, integrated with the same classification; misses_layer is null under "max").
  ReflectionMode reflection_mode = ReflectionMode::kOff;
  detail::ReflectionBasis reflection_basis;
  std::unique_ptr<WaveletMap> hits_layer, misses_layer;
  /// The clamps (boundsCounts): the misses of cell (ix, iy), of log-odds `l`, as if it were
  /// never hit: from misses_layer after a restart (kCounts), else from `l` (reflection.cpp).
  double unhitMisses(std::int64_t ix, std::int64_t iy, double l) const {
    if (reflection_mode == ReflectionMode::kCounts) {
      return static_cast<double>(misses_layer->value({ix, iy}));
    }
    return reflection_basis.missesOfUnhit(l);
  }
  /// unhitMisses() of the cell `code` (Morton, cell_runs.h) of the block whose first cell is
  /// (ix0, iy0): its position is decoded only where misses_layer holds the misses.
  double unhitMisses(std::int64_t ix0, std::int64_t iy0, std::uint32_t code, double l) const {
    if (reflection_mode != ReflectionMode::kCounts) return reflection_basis.missesOfUnhit(l);
    std::uint32_t lx, ly;
    detail::mortonCell(code, &lx, &ly);
    return unhitMisses(ix0 + lx, iy0 + ly, l);
  }
  detail::StoreCounts counts;  ///< live nodes (roots included), node groups and tiles
  std::uint64_t nodes_visited_last = 0;

  /// Recomputes a, the pending units and their multipliers, k_star, init from params (policy
  /// changes).
  void configure();

  detail::Node& child(detail::Node& n, int q) { return pool.group(n.children).n[q]; }
  const detail::Node& child(const detail::Node& n, int q) const {
    return pool.group(n.children).n[q];
  }
  bool hasChild(const detail::Node& n, int q) const { return (n.child_mask >> q) & 1u; }
  /// A tile node's cells (storage/tile.h).
  static bool hasTile(const detail::Node& n) { return (n.child_mask & detail::kTileBit) != 0; }
  /// Returns f(tile) for the tile of node n, a FloatTile or a WideTile (tiles.wide()).
  template <typename F>
  decltype(auto) withTile(const detail::Node& n, F&& f) {
    if (tiles.wide()) return f(tiles.wideTiles().group(n.children));
    return f(tiles.narrow().group(n.children));
  }
  template <typename F>
  decltype(auto) withTile(const detail::Node& n, F&& f) const {
    if (tiles.wide()) return f(tiles.wideTiles().group(n.children));
    return f(tiles.narrow().group(n.children));
  }
  /// Gives node n (tag flushed, no children) a tile, uniform at its average, observed as its
  /// knowledge bits say.
  void addTile(detail::NodeStore& store, detail::Node& n) {
    n.children = store.allocateTile();
    n.child_mask = detail::kTileBit;
    withTile(n, [&](auto& t) { detail::fillTile(&t, tile_level, n.known_any != 0); });
  }
  /// Frees the tile of node n when it carries nothing beyond n's average (tileUniform): n then
  /// has no children, and its knowledge bits are those of the tile.
  void dropTileIfUniform(detail::NodeStore& store, detail::Node& n) {
    const bool uniform = withTile(n, [&](const auto& t) {
      const detail::TileKnowledge k = detail::tileKnowledge(tile_level, t.known);
      n.known_all = k.all & 0xFu;  // 4-bit masks
      n.known_any = k.any & 0xFu;
      return detail::tileUniform(t, tile_level, prune_threshold);
    });
    if (!uniform) return;
    store.releaseTile(n.children);
    n.children = 0;
    n.child_mask = 0;
  }
  /// Makes every tile float, or wide (storage/tile.h), as the policy needs (configure()).
  void setTileKind(bool wide);

  /// Node groups and counts for one thread at a time: the pools' own free lists, the map's
  /// counts.
  detail::NodeStore serialStore() { return {pool, tiles, nullptr, &counts}; }

  /// Installs `m` as child q of `n` (allocating the group if needed); returns the stored node.
  detail::Node& installChild(detail::NodeStore& store, detail::Node& n, int q,
                             const detail::Node& m);
  detail::Node& installChild(detail::Node& n, int q, const detail::Node& m) {
    detail::NodeStore store = serialStore();
    return installChild(store, n, q, m);
  }
  /// Removes child q of `n` and its whole subtree.
  void removeChild(detail::NodeStore& store, detail::Node& n, int q);
  void removeChild(detail::Node& n, int q) {
    detail::NodeStore store = serialStore();
    removeChild(store, n, q);
  }
  /// Stores `m` as the root node of block `b`.
  static void installRoot(detail::NodeStore& store, detail::Block* b, const detail::Node& m) {
    b->root = m;
    b->has_root = true;
    store.nodeAdded();
  }
  /// Deletes the root node of block `b` and its subtree (the block becomes uniform).
  void removeRoot(detail::NodeStore& store, detail::Block* b) {
    freeSubtree(store, b->root);
    b->has_root = false;
    store.nodeRemoved();
  }
  void removeRoot(detail::Block* b) {
    detail::NodeStore store = serialStore();
    removeRoot(store, b);
  }
  /// Frees every node below `n` (not n itself).
  void freeSubtree(detail::NodeStore& store, detail::Node& n);

  /// Applies n's pending count to its details and hands it to its children (ALGORITHM.md F1).
  void flush(detail::Node& n);
  /// Adds `m` pending steps to n, flushing first if the 8-bit counter would overflow.
  void addPending(detail::Node& n, unsigned m);
  /// Applies every pending tag in the map (before a policy change or a save).
  void flushAll();

  /// The basis of the reflection map under params.
  detail::ReflectionBasis currentBasis() const;
  /// Starts the reflection map afresh from no hits and no misses: in the mode of params' policy
  /// when the occupancy is empty too (`fresh`), else in one that does not read the occupancy.
  void restartReflection(bool fresh);
  /// Before a policy change to `next`: the clamps' pairs brought up to date under params (their
  /// misses so far read from the occupancy, which the change may re-clamp at its next update).
  void settlePairs(const MapParams& next);
  /// After a policy change: restarts the reflection map if its basis changed (the counts of one
  /// policy mean something else under another), else re-parameterises its layers.
  void configureReflection();
  /// After a load: the file's reflection map (its mode, basis and layers; its hits are in the
  /// blocks already) when it was built under this map's basis and holds the layers its mode
  /// needs, else a restart.
  void adoptReflection(ReflectionMode mode, const detail::ReflectionBasis& basis,
                       std::unique_ptr<WaveletMap> hits, std::unique_ptr<WaveletMap> misses);
  /// The parameters of reflection layer `hits` (else misses) of a map with `main` in `mode`.
  static MapParams layerParams(const MapParams& main, bool hits, ReflectionMode mode);

  /// True when node `n` (after an update) carries no information beyond its parent's summary:
  /// no child, negligible details, uniform knowledge.
  bool isTrivial(const detail::Node& n) const {
    return n.child_mask == 0 && detail::maxAbsDetail(n) <= prune_threshold &&
           (n.known_any == 0 || n.known_all == 0xF);
  }

  /// Block lookup (nullptr when absent) and creation (uniform at the prior, unobserved).
  detail::Block* findBlock(std::int64_t bx, std::int64_t by);
  const detail::Block* findBlock(std::int64_t bx, std::int64_t by) const;
  detail::Block& getOrCreateBlock(std::int64_t bx, std::int64_t by);
  /// What the map holds for the scale-s cell (x, y) of the extent: its Haar average, read from the
  /// block root down (lazy tags applied on the way, nothing written), and the knowledge bits of the
  /// slot it was read from (the cell itself, or a uniform slot above it).
  struct SlotRead {
    double average;
    bool known_all, known_any;
  };
  SlotRead read(int s, std::int64_t x, std::int64_t y) const;
  /// Drops a block that holds nothing (uniform, unobserved, at the prior).
  void dropIfEmpty(std::int64_t bx, std::int64_t by);
  /// Erases block `key` (its nodes must be freed already); its spare groups go to the pool.
  void eraseBlock(std::uint64_t key);
};

// Hot helpers of the integration, inline so the shared library calls them without a PLT hop.

inline detail::Node& WaveletMap::Impl::installChild(detail::NodeStore& store, detail::Node& n,
                                                    int q, const detail::Node& m) {
  if (n.children == 0) n.children = store.allocate();
  n.child_mask = static_cast<std::uint8_t>(n.child_mask | (1u << q));
  detail::Node& c = child(n, q);
  c = m;
  store.nodeAdded();
  return c;
}

inline void WaveletMap::Impl::flush(detail::Node& n) {
  if (n.k == 0) return;
  const double m = multiplier(n.k);
  for (double& d : n.d) d *= m;
  if (hasTile(n)) {
    withTile(n, [m](auto& t) { detail::scaleTile(&t, m); });
  } else if (n.children != 0) {
    for (int q = 0; q < 4; ++q) {
      if (hasChild(n, q)) addPending(child(n, q), n.k);
    }
  }
  n.k = 0;
}

inline void WaveletMap::Impl::addPending(detail::Node& n, unsigned m) {
  if (n.k + m > k_cap) flush(n);
  n.k = static_cast<std::uint16_t>(n.k + m);
}

}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_STORAGE_MAP_IMPL_H_
