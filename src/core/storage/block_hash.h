// The hash of quadtree blocks: a block's average, root node and knowledge, keyed by its block
// indices (so the map grows without bound in every direction), and the cell <-> block index
// arithmetic. Part of WaveletMap's private storage; not installed, included only by src/core/*.
#ifndef WAVOG_MAPPING_SRC_CORE_STORAGE_BLOCK_HASH_H_
#define WAVOG_MAPPING_SRC_CORE_STORAGE_BLOCK_HASH_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "payloads/ndt_store.h"
#include "storage/node_pool.h"
#include "payloads/reflection_store.h"

namespace wavog {
namespace detail {

/// Parts of a block the split walk updates apart, at most (update/split_plan.h).
constexpr std::size_t kMaxBlockParts = 64;

/// One hashed block: a quadtree of block_levels levels, its average and its root node.
struct Block {
  double s = 0.0;          ///< mean log-odds of the block (exact, never lazy)
  Node root{};             ///< valid when has_root
  bool has_root = false;   ///< false: the block is uniform at s
  bool known_all = false;  ///< every cell observed
  bool known_any = false;  ///< some cell observed
  /// Node groups and tiles this block freed during integrations, reused by its next ones.
  Spares spare;
  /// The spare lists of the block's parts (update/split_plan.h: the slots split_levels below
  /// its root, which threads update apart).
  std::array<Spares, kMaxBlockParts> part_spare{};
  /// MapParams::ndt: the Gaussians of its cells (made with the first end-point in the block).
  std::unique_ptr<NdtCells> ndt;
  /// MapParams::reflection: the hits of its cells (made with the first hit in the block).
  std::unique_ptr<HitCells> hits;
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

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_STORAGE_BLOCK_HASH_H_
