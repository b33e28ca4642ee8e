// Private storage of WaveletMap: node pool, blocks, lazy-forgetting tags, and the shared
// slot logic (create / prune a child node) used by integration, region clearing and loading.
// Not installed; included only by src/core/*.cpp.
#ifndef WAVOG_MAPPING_SRC_CORE_MAP_IMPL_H_
#define WAVOG_MAPPING_SRC_CORE_MAP_IMPL_H_

#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "wavog_mapping/core/params.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog {
namespace detail {

/// One quadtree node at level l >= 1: the three Haar details of its 2x2 children, its children
/// (a group of 4 node slots in the pool; a missing child is a uniform block), the lazy forgetting
/// count and what is known of its children. Level-1 nodes have finest cells as children.
struct Node {
  float d[3] = {0.f, 0.f, 0.f};  ///< stored details dx, dy, dxy (true = stored * a^(pending k's))
  std::uint32_t children = 0;    ///< pool group of the 4 child slots; 0 = no child node
  std::uint8_t k = 0;            ///< pending forgetting steps for this node and its subtree
  std::uint8_t child_mask = 0;   ///< bit q: child node q exists in the group
  std::uint8_t known_all = 0;    ///< bit q: every finest cell of child q was observed
  std::uint8_t known_any = 0;    ///< bit q: some finest cell of child q was observed
};
static_assert(sizeof(Node) == 20, "Node layout grew");

struct NodeGroup {
  Node n[4];
};

/// Pool of node groups in fixed chunks: group addresses never move, index 0 is reserved (null).
class NodePool {
 public:
  NodePool() { clear(); }
  void clear() {
    chunks_.clear();
    free_.clear();
    next_ = 1;
    live_ = 0;
    addChunk();
  }
  std::uint32_t allocate() {
    std::uint32_t g;
    if (!free_.empty()) {
      g = free_.back();
      free_.pop_back();
    } else {
      if ((next_ >> kChunkBits) >= chunks_.size()) addChunk();
      g = next_++;
    }
    group(g) = NodeGroup{};
    ++live_;
    return g;
  }
  void release(std::uint32_t g) {
    free_.push_back(g);
    --live_;
  }
  NodeGroup& group(std::uint32_t g) { return chunks_[g >> kChunkBits][g & kChunkMask]; }
  const NodeGroup& group(std::uint32_t g) const { return chunks_[g >> kChunkBits][g & kChunkMask]; }
  /// Asks the CPU to fetch group g (at most two cache lines) ahead of its use.
  void prefetch(std::uint32_t g) const {
    const char* p = reinterpret_cast<const char*>(&group(g));
    __builtin_prefetch(p);
    __builtin_prefetch(p + sizeof(NodeGroup) - 1);
  }
  std::size_t liveGroups() const { return live_; }
  /// Bytes of the live groups plus bookkeeping.
  std::size_t bytes() const { return live_ * sizeof(NodeGroup) + overhead(); }
  /// Bytes of every allocated chunk plus bookkeeping.
  std::size_t bytesReserved() const {
    return chunks_.size() * (std::size_t{1} << kChunkBits) * sizeof(NodeGroup) + overhead();
  }

 private:
  std::size_t overhead() const {
    return free_.capacity() * sizeof(std::uint32_t) + chunks_.capacity() * sizeof(void*);
  }
  static constexpr std::uint32_t kChunkBits = 8;  // 256 groups (20 KiB) per chunk
  static constexpr std::uint32_t kChunkMask = (1u << kChunkBits) - 1;
  void addChunk() { chunks_.emplace_back(new NodeGroup[std::size_t{1} << kChunkBits]); }
  std::vector<std::unique_ptr<NodeGroup[]>> chunks_;
  std::vector<std::uint32_t> free_;
  std::uint32_t next_ = 1;
  std::size_t live_ = 0;
};

/// One hashed block: a quadtree of block_levels levels, its average and its root node.
struct Block {
  double s = 0.0;          ///< mean log-odds of the block (exact, never lazy)
  Node root;               ///< valid when has_root
  bool has_root = false;   ///< false: the block is uniform at s
  bool known_all = false;  ///< every cell observed
  bool known_any = false;  ///< some cell observed
};

inline std::uint64_t blockKey(std::int64_t bx, std::int64_t by) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(bx)) << 32) |
         static_cast<std::uint64_t>(static_cast<std::uint32_t>(by));
}
inline std::int64_t blockKeyX(std::uint64_t key) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(key >> 32));
}
inline std::int64_t blockKeyY(std::uint64_t key) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(key & 0xffffffffu));
}
struct BlockKeyHash {
  std::size_t operator()(std::uint64_t k) const {
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdULL;
    k ^= k >> 33;
    return static_cast<std::size_t>(k);
  }
};
using BlockMap = std::unordered_map<std::uint64_t, Block, BlockKeyHash>;

/// Floor division for cell -> block indices (arithmetic shift: works for negative cells).
inline std::int64_t floorShift(std::int64_t v, int bits) { return v >> bits; }
/// v * 2^bits for any sign (a left shift of a negative value is undefined in C++17).
inline std::int64_t scaleUp(std::int64_t v, int bits) { return v * (std::int64_t{1} << bits); }

/// Sets or clears `bit` in a knowledge mask.
inline void setBit(std::uint8_t* mask, std::uint8_t bit, bool on) {
  *mask = static_cast<std::uint8_t>(on ? (*mask | bit) : (*mask & ~bit));
}

/// Largest stored detail magnitude of a node (stored, without pending tags).
inline float maxAbsDetail(const Node& n) {
  const float a = std::fabs(n.d[0]), b = std::fabs(n.d[1]), c = std::fabs(n.d[2]);
  const float ab = a > b ? a : b;
  return ab > c ? ab : c;
}

}  // namespace detail

/// Everything a WaveletMap holds. Members are public to the core's own translation units.
struct WaveletMap::Impl {
  explicit Impl(const MapParams& p);

  MapParams params;
  int levels = 0;                 ///< block_levels
  double init = 0.0;              ///< prior log-odds of never-observed cells
  double a = 1.0;                 ///< 1 - gamma for "forget", else 1
  double prune_threshold = 1e-6;  ///< effective tau
  int k_star = 256;  ///< pending count at which a fully-E subtree is negligible (<= 255)
  std::array<double, 256> pow_a{};  ///< a^k

  detail::NodePool pool;
  detail::BlockMap blocks;
  std::size_t nodes = 0;  ///< live nodes (roots included)
  std::uint64_t nodes_visited_last = 0;

  /// Recomputes a, pow_a, k_star, init from params (policy changes).
  void configure();

  detail::Node& child(detail::Node& n, int q) { return pool.group(n.children).n[q]; }
  const detail::Node& child(const detail::Node& n, int q) const {
    return pool.group(n.children).n[q];
  }
  bool hasChild(const detail::Node& n, int q) const { return (n.child_mask >> q) & 1u; }

  /// Installs `m` as child q of `n` (allocating the group if needed); returns the stored node.
  detail::Node& installChild(detail::Node& n, int q, const detail::Node& m);
  /// Removes child q of `n` and its whole subtree.
  void removeChild(detail::Node& n, int q);
  /// Stores `m` as the root node of block `b`.
  void installRoot(detail::Block* b, const detail::Node& m) {
    b->root = m;
    b->has_root = true;
    ++nodes;
  }
  /// Deletes the root node of block `b` and its subtree (the block becomes uniform).
  void removeRoot(detail::Block* b) {
    freeSubtree(b->root);
    b->has_root = false;
    --nodes;
  }
  /// Frees every node below `n` (not n itself).
  void freeSubtree(detail::Node& n);

  /// Applies n's pending count to its details and hands it to its children (ALGORITHM.md F1).
  void flush(detail::Node& n);
  /// Adds `m` pending steps to n, flushing first if the 8-bit counter would overflow.
  void addPending(detail::Node& n, unsigned m);
  /// Applies every pending tag in the map (before a policy change or a save).
  void flushAll();

  /// True when node `n` (after an update) carries no information beyond its parent's summary:
  /// no child, negligible details, uniform knowledge.
  bool isTrivial(const detail::Node& n) const {
    return n.child_mask == 0 && detail::maxAbsDetail(n) <= prune_threshold &&
           (n.known_any == 0 || n.known_all == 0xF);
  }

  /// A temporary node standing for a missing child (a uniform block) about to be refined.
  static detail::Node uniformSlot(bool all, bool any) {
    detail::Node n;
    n.known_all = all ? 0xF : 0;
    n.known_any = any ? 0xF : 0;
    return n;
  }
  /// After slot node `m` was updated (the stored child when `existed`, else a temporary from
  /// uniformSlot): reports the slot's knowledge, deletes a stored node that became trivial and
  /// stores a temporary that did not. install(m) stores a node, remove() deletes the stored one.
  template <typename Install, typename Remove>
  void settleSlot(const detail::Node& m, bool existed, bool* all, bool* any, Install install,
                  Remove remove) {
    *all = m.known_all == 0xF;
    *any = m.known_any != 0;
    if (isTrivial(m)) {
      if (existed) remove();
    } else if (!existed) {
      install(m);
    }
  }

  /// Block lookup (nullptr when absent) and creation (uniform at the prior, unobserved).
  detail::Block* findBlock(std::int64_t bx, std::int64_t by);
  const detail::Block* findBlock(std::int64_t bx, std::int64_t by) const;
  detail::Block& getOrCreateBlock(std::int64_t bx, std::int64_t by);
  /// Drops a block that holds nothing (uniform, unobserved, at the prior).
  void dropIfEmpty(std::int64_t bx, std::int64_t by);
};

// Hot helpers of the integration, inline so the shared library calls them without a PLT hop.

inline detail::Node& WaveletMap::Impl::installChild(detail::Node& n, int q, const detail::Node& m) {
  if (n.children == 0) n.children = pool.allocate();
  n.child_mask = static_cast<std::uint8_t>(n.child_mask | (1u << q));
  detail::Node& c = child(n, q);
  c = m;
  ++nodes;
  return c;
}

inline void WaveletMap::Impl::flush(detail::Node& n) {
  if (n.k == 0) return;
  const float m = static_cast<float>(pow_a[n.k]);
  for (float& d : n.d) d *= m;
  if (n.children != 0) {
    for (int q = 0; q < 4; ++q) {
      if (hasChild(n, q)) addPending(child(n, q), n.k);
    }
  }
  n.k = 0;
}

inline void WaveletMap::Impl::addPending(detail::Node& n, unsigned m) {
  if (n.k + m > 255u) flush(n);
  n.k = static_cast<std::uint8_t>(n.k + m);
}

}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_MAP_IMPL_H_
