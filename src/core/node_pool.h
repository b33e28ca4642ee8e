// Quadtree nodes and the pool that stores them: a node holds the three Haar details of its 2x2
// children, its lazy forgetting count and what is known of its children; groups of four child
// nodes live in a pool of fixed chunks (addresses never move). Part of WaveletMap's private
// storage; not installed, included only by src/core/* and the core tests.
#ifndef WAVOG_MAPPING_SRC_CORE_NODE_POOL_H_
#define WAVOG_MAPPING_SRC_CORE_NODE_POOL_H_

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <vector>

namespace wavog {
namespace detail {

/// One quadtree node at level l >= 1: the three Haar details of its 2x2 children, its children
/// (a group of 4 node slots in the pool; a missing child is a uniform block), the lazy forgetting
/// count and what is known of its children. Level-1 nodes have finest cells as children.
/// A trivial type: `Node{}` is the empty node (all zero); `Node n;` is uninitialised, so that the
/// pool's chunks need not be cleared (allocate() clears each group it hands out).
struct Node {
  float d[3];               ///< stored details dx, dy, dxy (true = stored * a^(pending k's))
  std::uint32_t children;   ///< pool group of the 4 child slots; 0 = no child node
  std::uint8_t k;           ///< pending forgetting steps for this node and its subtree
  std::uint8_t child_mask;  ///< bit q: child node q exists in the group
  std::uint8_t known_all;   ///< bit q: every finest cell of child q was observed
  std::uint8_t known_any;   ///< bit q: some finest cell of child q was observed
};
static_assert(sizeof(Node) == 20, "Node layout grew");
static_assert(std::is_trivial<Node>::value, "Node must stay trivial (uncleared pool chunks)");

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

/// Largest stored detail magnitude of a node (stored, without pending tags).
inline float maxAbsDetail(const Node& n) {
  const float a = std::fabs(n.d[0]), b = std::fabs(n.d[1]), c = std::fabs(n.d[2]);
  const float ab = a > b ? a : b;
  return ab > c ? ab : c;
}

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_NODE_POOL_H_
