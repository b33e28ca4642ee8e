// A scan's update of blocks split below their roots (issue 29): so that the threads of one scan
// share the work of one block (indoors most of a scan lies in the block around the sensor), the
// top levels of each block are walked first on the calling thread, down to the slots
// split_levels below the root (the parts); the parts are then updated independently, each from
// its own spare node groups, by any thread; last, on the calling thread again, the parts' average
// changes fold into the nodes above them and every slot of the top levels is settled as
// refineSlot() settles it. The three steps: Integrator::planBlock, visitPart, settle
// (quadtree_update.h). The result does not depend on the thread count: the same blocks are split
// the same way with one thread. Not installed; included only by src/core/update/*.
#ifndef WAVOG_MAPPING_SRC_CORE_UPDATE_SPLIT_PLAN_H_
#define WAVOG_MAPPING_SRC_CORE_UPDATE_SPLIT_PLAN_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "classify/scan_classifier.h"
#include "storage/block_hash.h"

namespace wavog {
namespace detail {

/// Levels below a block's root at which it is split: 16 parts of 128 x 128 cells in a block of
/// 9 levels. Parts stay at level 3 or above (the walk's general case); blocks of fewer than 5
/// levels split less, of 3 or fewer not at all.
constexpr int kSplitLevels = 3;
static_assert(std::size_t{1} << (2 * kSplitLevels) <= kMaxBlockParts, "Block::part_spare");
/// A scan's blocks are split when it touches at most this many: indoors a scan's work lies in
/// the one or two blocks around the sensor; a scan of many blocks gives every thread whole
/// blocks, and splitting them would only add the planning, done on one thread, to its time
/// (80 m / 5 cm, 22 blocks per scan, 2 threads over 1: 1.48x split, 1.73x not).
constexpr std::size_t kSplitMaxBlocks = 8;
inline int splitLevels(int block_levels) {
  const int d = block_levels - 3;
  return d < kSplitLevels ? (d > 0 ? d : 0) : kSplitLevels;
}

/// A slot of a split block's top levels whose update waits: a frame (a node whose children's
/// changes fold into it) or a part (updated on its own by visitPart).
struct SplitTask {
  Block* block = nullptr;
  Node* parent = nullptr;  ///< nullptr: the block's root slot; else child q of *parent
  int q = 0;
  Node* node = nullptr;  ///< the slot's node (stored by the planning)
  long up = -1;          ///< the task of the parent slot; -1 for the root
  bool part = false;
  std::array<double, 4> delta{};  ///< a frame: the changes of its children's averages
  double ds = 0.0;                ///< the change of the slot's average
  // A part: what visitNode needs, and the spare groups it takes nodes from.
  SquareInfo box;
  int level = 0;
  std::int64_t ix0 = 0, iy0 = 0;
  double s = 0.0;
  Spares* spare = nullptr;   ///< its spare lists (NodeStore)
  std::uint64_t visits = 0;  ///< the nodes its update visited (updateParts)
};

/// The tasks of one scan's split blocks, in the planning's (depth-first) order, and the indices
/// of its parts; and what the parts of the last parallel scan cost.
struct SplitPlan {
  std::vector<SplitTask> tasks;
  std::vector<std::size_t> parts;
  /// The last parallel scan's parts, sorted: their spare list's address (a block's part) and
  /// their visits, which predict what the same part costs in the next scan (the order of the
  /// parts, integrate.cpp). Kept by clear().
  std::vector<std::pair<std::uintptr_t, std::uint64_t>> last_visits;
  void clear() {
    tasks.clear();
    parts.clear();
  }
};

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_UPDATE_SPLIT_PLAN_H_
