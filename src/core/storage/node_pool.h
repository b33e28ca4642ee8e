// Quadtree nodes and the pool that stores them: a node holds the three Haar details of its 2x2
// children, its lazy forgetting count and what is known of its children; groups of four child
// nodes live in a pool of fixed chunks (addresses never move). Part of WaveletMap's private
// storage; not installed, included only by src/core/* and the core tests.
#ifndef WAVOG_MAPPING_SRC_CORE_STORAGE_NODE_POOL_H_
#define WAVOG_MAPPING_SRC_CORE_STORAGE_NODE_POOL_H_

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

namespace wavog {
namespace detail {

/// One quadtree node at level l >= 1: the three Haar details of its 2x2 children, its children
/// (a group of 4 node slots in the pool; a missing child is a uniform block), the pending lazy
/// forgetting (k units, see WaveletMap::Impl::multiplier) and what is known of its children.
/// Level-1 nodes have finest cells as children. A trivial type: `Node{}` is the empty node (all
/// zero); `Node n;` is uninitialised, so that the pool's chunks need not be cleared (allocate()
/// clears each group it hands out).
struct Node {
  /// Stored details dx, dy, dxy (true = stored * multiplier(k's)). Double: a cell is its block's
  /// average plus its ancestors' details, so beside a cell of log-odds L the float details could
  /// only hold it to about L * 2^-24 per level, and every update rounded them again (issue 37: an
  /// unbounded policy's 24,000 scans of one fan moved unobserved cells next to it by 1.2).
  double d[3];
  std::uint32_t children;      ///< pool group of the 4 child slots; 0 = no child node
  std::uint16_t k;             ///< pending forgetting units for this node and its subtree
  std::uint8_t child_mask;     ///< bit q: child node q exists in the group
  std::uint8_t known_all : 4;  ///< bit q: every finest cell of child q was observed
  std::uint8_t known_any : 4;  ///< bit q: some finest cell of child q was observed
};
static_assert(sizeof(Node) == 32, "Node layout grew");
static_assert(std::is_trivial<Node>::value, "Node must stay trivial (uncleared pool chunks)");

struct NodeGroup {
  Node n[4];
};

/// Pool of node groups in fixed chunks: group addresses never move, index 0 is reserved (null).
/// Thread-safety: group() and fresh() may be called from several threads at once (a parallel
/// integration, integrate.cpp) once reserveFresh() has made room for every group they will take;
/// everything else is for one thread at a time. New indices come from one atomic counter and each
/// chunk is made by the first thread to need it, so the pool's size (chunks, table, counts) does
/// not depend on how threads interleave, only on how many new groups were taken.
class NodePool {
 public:
  NodePool() { clear(); }
  ~NodePool() { releaseChunks(); }
  NodePool(const NodePool&) = delete;
  NodePool& operator=(const NodePool&) = delete;
  NodePool(NodePool&& o) noexcept { *this = std::move(o); }
  NodePool& operator=(NodePool&& o) noexcept {
    if (this == &o) return *this;
    releaseChunks();
    table_ = std::move(o.table_);
    capacity_ = o.capacity_;
    next_.store(o.next_.load(std::memory_order_relaxed), std::memory_order_relaxed);
    free_ = std::move(o.free_);
    live_ = o.live_;
    o.capacity_ = 0;
    o.clear();
    return *this;
  }

  void clear() {
    releaseChunks();
    free_.clear();
    free_.shrink_to_fit();
    next_.store(1, std::memory_order_relaxed);
    live_ = 0;
    growTable(1);
    chunk(0);
  }
  /// A cleared group from the pool's own free list or a new one (one thread at a time).
  std::uint32_t allocate() {
    std::uint32_t g;
    if (!free_.empty()) {
      g = free_.back();
      free_.pop_back();
      group(g) = NodeGroup{};
    } else {
      g = fresh();
    }
    ++live_;
    return g;
  }
  /// Gives group g back to the pool's own free list (one thread at a time).
  void release(std::uint32_t g) {
    free_.push_back(g);
    --live_;
  }
  /// Puts group g, not counted as live, on the pool's own free list (one thread at a time).
  void recycle(std::uint32_t g) { free_.push_back(g); }
  /// Moves up to `count` groups of the pool's own free list to the spare list whose first group
  /// is *spare (one thread at a time).
  void lend(std::size_t count, std::uint32_t* spare) {
    for (; count > 0 && !free_.empty(); --count) {
      pushSpare(spare, free_.back());
      free_.pop_back();
    }
  }
  /// Spare lists (a block's, or a part's of a block, NodeStore): the groups are chained through
  /// their own storage (a spare group holds no node), *list is the first one, 0 ends the list.
  void pushSpare(std::uint32_t* list, std::uint32_t g) {
    group(g).n[0].children = *list;
    *list = g;
  }
  /// The first group of a non-empty spare list, taken off it (not cleared).
  std::uint32_t popSpare(std::uint32_t* list) {
    const std::uint32_t g = *list;
    *list = group(g).n[0].children;
    return g;
  }
  /// Puts every group of a spare list on the pool's own free list (not counted as live).
  void recycleSpares(std::uint32_t* list) {
    while (*list != 0) recycle(popSpare(list));
  }
  /// A cleared, never used group. Safe from several threads within the reserved room; it does
  /// not count the group as live (the caller does, see NodeStore).
  std::uint32_t fresh() {
    const std::uint32_t g = next_.fetch_add(1, std::memory_order_relaxed);
    const std::size_t c = g >> kChunkBits;
    if (c >= capacity_) growTable(c + 1);  // only without reserveFresh(): single-threaded use
    NodeGroup* p = chunk(c);
    p[g & kChunkMask] = NodeGroup{};
    return g;
  }
  /// Makes room in the chunk table for `groups` more fresh() calls (one thread, before a
  /// parallel region); the table grows by doubling.
  void reserveFresh(std::size_t groups) {
    const std::size_t need = ((next_.load(std::memory_order_relaxed) + groups) >> kChunkBits) + 1;
    if (need > capacity_) growTable(std::max(need, 2 * capacity_));
  }
  /// Adds `d` (modulo 2^64, so a negative change is a wrapped one) to the live-group count.
  void addLive(std::size_t d) { live_ += d; }
  std::size_t* liveCounter() { return &live_; }

  NodeGroup& group(std::uint32_t g) {
    return table_[g >> kChunkBits].load(std::memory_order_relaxed)[g & kChunkMask];
  }
  const NodeGroup& group(std::uint32_t g) const {
    return table_[g >> kChunkBits].load(std::memory_order_relaxed)[g & kChunkMask];
  }
  /// Asks the CPU to fetch group g (at most two cache lines) ahead of its use.
  void prefetch(std::uint32_t g) const {
    const char* p = reinterpret_cast<const char*>(&group(g));
    __builtin_prefetch(p);
    __builtin_prefetch(p + sizeof(NodeGroup) - 1);
  }
  std::size_t liveGroups() const { return live_; }
  /// Chunks ever made (they are kept until clear()).
  std::size_t chunks() const {
    return (static_cast<std::size_t>(next_.load(std::memory_order_relaxed)) + kChunkMask) >>
           kChunkBits;
  }
  /// Bytes of the live groups plus bookkeeping.
  std::size_t bytes() const {
    return live_ * sizeof(NodeGroup) + free_.capacity() * sizeof(std::uint32_t) +
           chunks() * sizeof(void*);
  }
  /// Bytes of every allocated chunk plus bookkeeping.
  std::size_t bytesReserved() const {
    return chunks() * (std::size_t{1} << kChunkBits) * sizeof(NodeGroup) +
           free_.capacity() * sizeof(std::uint32_t) + capacity_ * sizeof(void*);
  }

 private:
  static constexpr std::uint32_t kChunkBits = 8;  // 256 groups (32 KiB) per chunk
  static constexpr std::uint32_t kChunkMask = (1u << kChunkBits) - 1;
  using Slot = std::atomic<NodeGroup*>;

  // Chunk c, made now if no thread has made it yet (the loser of a race frees its copy).
  NodeGroup* chunk(std::size_t c) {
    NodeGroup* p = table_[c].load(std::memory_order_acquire);
    if (p != nullptr) return p;
    auto* made = new NodeGroup[std::size_t{1} << kChunkBits];
    if (table_[c].compare_exchange_strong(p, made, std::memory_order_acq_rel,
                                          std::memory_order_acquire)) {
      return made;
    }
    delete[] made;
    return p;
  }
  void growTable(std::size_t capacity) {
    std::unique_ptr<Slot[]> t(new Slot[capacity]);
    for (std::size_t i = 0; i < capacity; ++i) {
      t[i].store(i < capacity_ ? table_[i].load(std::memory_order_relaxed) : nullptr,
                 std::memory_order_relaxed);
    }
    table_ = std::move(t);
    capacity_ = capacity;
  }
  void releaseChunks() {
    for (std::size_t i = 0; i < capacity_; ++i) delete[] table_[i].load(std::memory_order_relaxed);
    table_.reset();
    capacity_ = 0;
  }

  std::unique_ptr<Slot[]> table_;  // chunk pointers; null until made
  std::size_t capacity_ = 0;       // slots in table_
  std::atomic<std::uint32_t> next_{1};
  std::vector<std::uint32_t> free_;
  std::size_t live_ = 0;
};

/// Where the node operations of one thread take node groups from and give them back to, and the
/// counts they change: the pool's own free list (one thread at a time), or, while a block (or a
/// part of one, update/split_plan.h) is integrated, its spare list (so that a block reuses only
/// its own groups and the map's size does not depend on which thread integrated which block),
/// then fresh ones.
/// `nodes` and `groups` point at the counters to change (modulo 2^64: a thread's own counters
/// may go below zero and are added to the map's afterwards).
class NodeStore {
 public:
  NodeStore(NodePool& pool, std::uint32_t* spare, std::size_t* nodes,
            std::size_t* groups)
      : pool_(pool), spare_(spare), nodes_(nodes), groups_(groups) {}
  NodePool& pool() const { return pool_; }
  /// Switches to the spare list of another block or part (NodePool::pushSpare).
  void useSpare(std::uint32_t* spare) { spare_ = spare; }
  std::uint32_t allocate() {
    if (spare_ == nullptr) return pool_.allocate();
    std::uint32_t g;
    if (*spare_ != 0) {
      g = pool_.popSpare(spare_);
      pool_.group(g) = NodeGroup{};
    } else {
      g = pool_.fresh();
    }
    ++*groups_;
    return g;
  }
  void release(std::uint32_t g) {
    if (spare_ == nullptr) {
      pool_.release(g);
      return;
    }
    pool_.pushSpare(spare_, g);
    --*groups_;
  }
  void nodeAdded() { ++*nodes_; }
  void nodeRemoved() { --*nodes_; }

 private:
  NodePool& pool_;
  std::uint32_t* spare_;
  std::size_t* nodes_;
  std::size_t* groups_;
};

/// Largest stored detail magnitude of a node (stored, without pending tags).
inline double maxAbsDetail(const Node& n) {
  const double a = std::fabs(n.d[0]), b = std::fabs(n.d[1]), c = std::fabs(n.d[2]);
  const double ab = a > b ? a : b;
  return ab > c ? ab : c;
}

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_STORAGE_NODE_POOL_H_
