// Quadtree nodes and the pools that store them: a node holds the three Haar details of its 2x2
// children, its lazy forgetting count and what is known of its children; groups of four child
// nodes, and the tiles of the tile nodes (tile.h), live in pools of fixed chunks (addresses never
// move). Part of WaveletMap's private storage; not installed, included only by src/core/* and the
// core tests.
#ifndef WAVOG_MAPPING_SRC_CORE_STORAGE_NODE_POOL_H_
#define WAVOG_MAPPING_SRC_CORE_STORAGE_NODE_POOL_H_

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include "storage/tile.h"

namespace wavog {
namespace detail {

/// One quadtree node at a level at or above the tile level (storage/tile.h): the three Haar
/// details of its 2x2 children, its children (a group of 4 node slots in the pool; a missing child
/// is a uniform block), the pending lazy forgetting (k units, see WaveletMap::Impl::multiplier)
/// and what is known of its children. A node of the tile level has no details and no child nodes:
/// `children` is the index of its tile (child_mask kTileBit). A trivial type: `Node{}` is the
/// empty node (all zero); `Node n;` is uninitialised, so that the pool's chunks need not be
/// cleared (allocate() clears each group it hands out).
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

/// Pool of elements T (node groups, tiles) in fixed chunks: addresses never move, index 0 is
/// reserved (null).
/// Thread-safety: group() and fresh() may be called from several threads at once (a parallel
/// integration, integrate.cpp) once reserveFresh() has made room for every group they will take;
/// everything else is for one thread at a time. New indices come from one atomic counter and each
/// chunk is made by the first thread to need it, so the pool's size (chunks, table, counts) does
/// not depend on how threads interleave, only on how many new groups were taken.
template <typename T>
class ChunkPool {
 public:
  ChunkPool() { clear(); }
  ~ChunkPool() { releaseChunks(); }
  ChunkPool(const ChunkPool&) = delete;
  ChunkPool& operator=(const ChunkPool&) = delete;
  ChunkPool(ChunkPool&& o) noexcept { *this = std::move(o); }
  ChunkPool& operator=(ChunkPool&& o) noexcept {
    if (this == &o) return *this;
    releaseChunks();
    table_ = std::move(o.table_);
    capacity_ = o.capacity_;
    next_.store(o.next_.load(std::memory_order_relaxed), std::memory_order_relaxed);
    free_ = std::move(o.free_);
    o.capacity_ = 0;
    o.clear();
    return *this;
  }

  void clear() {
    releaseChunks();
    free_.clear();
    free_.shrink_to_fit();
    next_.store(1, std::memory_order_relaxed);
    growTable(1);
    chunk(0);
  }
  /// A cleared element from the pool's own free list or a new one (one thread at a time). The
  /// pool counts none of them: the map does (StoreCounts).
  std::uint32_t allocate(bool cleared = true) {
    if (free_.empty()) return fresh(cleared);
    const std::uint32_t g = free_.back();
    free_.pop_back();
    if (cleared) group(g) = T{};
    return g;
  }
  /// Gives element g back to the pool's own free list (one thread at a time).
  void release(std::uint32_t g) { free_.push_back(g); }
  /// The same for an element not counted as live (a spare one).
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
    std::memcpy(&group(g), list, sizeof(std::uint32_t));
    *list = g;
  }
  /// The first group of a non-empty spare list, taken off it (not cleared).
  std::uint32_t popSpare(std::uint32_t* list) {
    const std::uint32_t g = *list;
    std::memcpy(list, &group(g), sizeof(std::uint32_t));
    return g;
  }
  /// Puts every group of a spare list on the pool's own free list (not counted as live).
  void recycleSpares(std::uint32_t* list) {
    while (*list != 0) recycle(popSpare(list));
  }
  /// A never used element, cleared unless `cleared` is false. Safe from several threads within the
  /// reserved room; it does not count the element as live (the caller does, see NodeStore).
  std::uint32_t fresh(bool cleared = true) {
    const std::uint32_t g = next_.fetch_add(1, std::memory_order_relaxed);
    const std::size_t c = g >> kChunkBits;
    if (c >= capacity_) growTable(c + 1);  // only without reserveFresh(): single-threaded use
    T* p = chunk(c);
    if (cleared) p[g & kChunkMask] = T{};
    return g;
  }
  /// Makes room in the chunk table for `groups` more fresh() calls (one thread, before a
  /// parallel region); the table grows by doubling.
  void reserveFresh(std::size_t groups) {
    const std::size_t need = ((next_.load(std::memory_order_relaxed) + groups) >> kChunkBits) + 1;
    if (need > capacity_) growTable(std::max(need, 2 * capacity_));
  }
  T& group(std::uint32_t g) {
    return table_[g >> kChunkBits].load(std::memory_order_relaxed)[g & kChunkMask];
  }
  const T& group(std::uint32_t g) const {
    return table_[g >> kChunkBits].load(std::memory_order_relaxed)[g & kChunkMask];
  }
  /// Asks the CPU to fetch group g (at most two cache lines) ahead of its use.
  void prefetch(std::uint32_t g) const {
    const char* p = reinterpret_cast<const char*>(&group(g));
    __builtin_prefetch(p);
    __builtin_prefetch(p + sizeof(T) - 1);
  }
  /// Chunks ever made (they are kept until clear()).
  std::size_t chunks() const {
    return (static_cast<std::size_t>(next_.load(std::memory_order_relaxed)) + kChunkMask) >>
           kChunkBits;
  }
  /// Bytes of `live` elements plus bookkeeping.
  std::size_t bytes(std::size_t live) const {
    return live * sizeof(T) + free_.capacity() * sizeof(std::uint32_t) + chunks() * sizeof(void*);
  }
  /// Bytes of every allocated chunk plus bookkeeping.
  std::size_t bytesReserved() const {
    return chunks() * (std::size_t{1} << kChunkBits) * sizeof(T) +
           free_.capacity() * sizeof(std::uint32_t) + capacity_ * sizeof(void*);
  }

 private:
  static constexpr std::uint32_t kChunkBits = 8;  // 256 groups (32 KiB) per chunk
  static constexpr std::uint32_t kChunkMask = (1u << kChunkBits) - 1;
  using Slot = std::atomic<T*>;

  // Chunk c, made now if no thread has made it yet (the loser of a race frees its copy).
  T* chunk(std::size_t c) {
    T* p = table_[c].load(std::memory_order_acquire);
    if (p != nullptr) return p;
    auto* made = new T[std::size_t{1} << kChunkBits];
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
};

using NodePool = ChunkPool<NodeGroup>;

/// The tiles of a map: float ones, or wide (double) ones under the unbounded policies
/// (storage/tile.h); a map holds one kind at a time, in its pool (the same indices either way).
class TilePool {
 public:
  bool wide() const { return wide_; }
  /// Switches the kind of new tiles (the map converts its tiles and spares first).
  void setWide(bool wide) { wide_ = wide; }
  ChunkPool<FloatTile>& narrow() { return narrow_; }
  ChunkPool<WideTile>& wideTiles() { return wide_tiles_; }
  const ChunkPool<FloatTile>& narrow() const { return narrow_; }
  const ChunkPool<WideTile>& wideTiles() const { return wide_tiles_; }

  void clear() {
    narrow_.clear();
    wide_tiles_.clear();
  }
  std::uint32_t allocate() { return wide_ ? wide_tiles_.allocate(false) : narrow_.allocate(false); }
  std::uint32_t fresh() { return wide_ ? wide_tiles_.fresh(false) : narrow_.fresh(false); }
  void release(std::uint32_t t) { wide_ ? wide_tiles_.release(t) : narrow_.release(t); }
  void lend(std::size_t count, std::uint32_t* spare) {
    wide_ ? wide_tiles_.lend(count, spare) : narrow_.lend(count, spare);
  }
  void pushSpare(std::uint32_t* list, std::uint32_t t) {
    wide_ ? wide_tiles_.pushSpare(list, t) : narrow_.pushSpare(list, t);
  }
  std::uint32_t popSpare(std::uint32_t* list) {
    return wide_ ? wide_tiles_.popSpare(list) : narrow_.popSpare(list);
  }
  void recycleSpares(std::uint32_t* list) {
    wide_ ? wide_tiles_.recycleSpares(list) : narrow_.recycleSpares(list);
  }
  void reserveFresh(std::size_t tiles) {
    wide_ ? wide_tiles_.reserveFresh(tiles) : narrow_.reserveFresh(tiles);
  }
  std::size_t bytes(std::size_t live) const {
    return wide_ ? wide_tiles_.bytes(live) : narrow_.bytes(live);
  }
  std::size_t bytesReserved() const {
    return narrow_.bytesReserved() + wide_tiles_.bytesReserved();
  }

 private:
  ChunkPool<FloatTile> narrow_;
  ChunkPool<WideTile> wide_tiles_;
  bool wide_ = false;
};

/// The spare lists of a block or of a part of one (ChunkPool::pushSpare): node groups and tiles.
struct Spares {
  std::uint32_t groups = 0, tiles = 0;
};

/// Counts of what a map (or one thread's share of an integration) holds: nodes, node groups,
/// tiles (modulo 2^64: a thread's own counts may go below zero and are added to the map's
/// afterwards).
struct StoreCounts {
  std::size_t nodes = 0, groups = 0, tiles = 0;
};

/// Where the node operations of one thread take node groups and tiles from and give them back
/// to, and the counts they change: the pools' own free lists (one thread at a time), or, while a
/// block (or a part of one, update/split_plan.h) is integrated, its spare lists (so that a block
/// reuses only its own groups and tiles and the map's size does not depend on which thread
/// integrated which block), then fresh ones.
class NodeStore {
 public:
  NodeStore(NodePool& pool, TilePool& tiles, Spares* spare, StoreCounts* counts)
      : pool_(pool), tiles_(tiles), spare_(spare), counts_(counts) {}
  NodePool& pool() const { return pool_; }
  TilePool& tiles() const { return tiles_; }
  /// Switches to the spare lists of another block or part.
  void useSpare(Spares* spare) { spare_ = spare; }
  std::uint32_t allocate() {
    ++counts_->groups;
    return spare_ == nullptr ? pool_.allocate() : take(pool_, &spare_->groups);
  }
  void release(std::uint32_t g) {
    --counts_->groups;
    if (spare_ == nullptr) {
      pool_.release(g);
    } else {
      pool_.pushSpare(&spare_->groups, g);
    }
  }
  /// A tile, not cleared (the caller fills it).
  std::uint32_t allocateTile() {
    ++counts_->tiles;
    if (spare_ == nullptr) return tiles_.allocate();
    return spare_->tiles != 0 ? tiles_.popSpare(&spare_->tiles) : tiles_.fresh();
  }
  void releaseTile(std::uint32_t t) {
    --counts_->tiles;
    if (spare_ == nullptr) {
      tiles_.release(t);
    } else {
      tiles_.pushSpare(&spare_->tiles, t);
    }
  }
  void nodeAdded() { ++counts_->nodes; }
  void nodeRemoved() { --counts_->nodes; }

 private:
  template <typename T>
  static std::uint32_t take(ChunkPool<T>& p, std::uint32_t* spare) {
    if (*spare == 0) return p.fresh();
    const std::uint32_t g = p.popSpare(spare);
    p.group(g) = T{};
    return g;
  }

  NodePool& pool_;
  TilePool& tiles_;
  Spares* spare_;
  StoreCounts* counts_;
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
