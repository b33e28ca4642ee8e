// Slots of the quadtree: the places a node can stand in, a block's root (RootSlot) or child q of a
// node (ChildSlot), each with the knowledge bits of its cells. An update reads a slot's node (or a
// temporary uniform one when it has none), changes it, and settles the slot: a stored node that
// became trivial is deleted, a temporary that did not is stored. Used by the integration and by
// region clearing; node groups come from and go to the slot's NodeStore. Not installed; included
// only by src/core/*.
#ifndef WAVOG_MAPPING_SRC_CORE_UPDATE_MAP_SLOT_H_
#define WAVOG_MAPPING_SRC_CORE_UPDATE_MAP_SLOT_H_

#include <array>
#include <cstdint>

#include "storage/map_impl.h"
#include "wavog_mapping/core/haar.h"
#include "wavog_mapping/core/limits.h"

namespace wavog {
namespace detail {

/// The root slot of block `b`.
class RootSlot {
 public:
  RootSlot(WaveletMap::Impl& impl, NodeStore& store, Block& b)
      : impl_(impl), store_(store), b_(b) {}
  WaveletMap::Impl& impl() const { return impl_; }
  /// The stored node, or nullptr when the block is uniform.
  Node* node() const { return b_.has_root ? &b_.root : nullptr; }
  bool knownAll() const { return b_.known_all; }
  bool knownAny() const { return b_.known_any; }
  void setKnown(bool all, bool any) {
    b_.known_all = all;
    b_.known_any = any;
  }
  void install(const Node& m) { WaveletMap::Impl::installRoot(store_, &b_, m); }
  void remove() { impl_.removeRoot(store_, &b_); }

 private:
  WaveletMap::Impl& impl_;
  NodeStore& store_;
  Block& b_;
};

/// The slot of child q of node `parent`.
class ChildSlot {
 public:
  ChildSlot(WaveletMap::Impl& impl, NodeStore& store, Node& parent, int q)
      : impl_(impl),
        store_(store),
        parent_(parent),
        q_(q),
        bit_(static_cast<std::uint8_t>(1u << q)) {}
  WaveletMap::Impl& impl() const { return impl_; }
  /// The stored child node, or nullptr when the child is uniform.
  Node* node() const { return impl_.hasChild(parent_, q_) ? &impl_.child(parent_, q_) : nullptr; }
  bool knownAll() const { return (parent_.known_all & bit_) != 0; }
  bool knownAny() const { return (parent_.known_any & bit_) != 0; }
  void setKnown(bool all, bool any) {
    parent_.known_all = withBit(parent_.known_all, bit_, all) & 0xFu;  // 4-bit masks
    parent_.known_any = withBit(parent_.known_any, bit_, any) & 0xFu;
  }
  void install(const Node& m) { impl_.installChild(store_, parent_, q_, m); }
  void remove() { impl_.removeChild(store_, parent_, q_); }

 private:
  WaveletMap::Impl& impl_;
  NodeStore& store_;
  Node& parent_;
  int q_;
  std::uint8_t bit_;
};

/// Refines `slot` whose stored node is `stored` (slot.node()): update(m) changes m, the stored
/// node or, when there is none, a temporary uniform node with the slot's knowledge; then the
/// slot takes m's knowledge, a stored node that became trivial is deleted and a temporary that
/// did not is stored. Returns what update returned (the change of the slot's average).
template <typename Slot, typename Update>
[[gnu::always_inline]] inline double refineSlot(Slot& slot, Node* stored, Update update) {
  Node tmp{};
  tmp.known_all = slot.knownAll() ? 0xF : 0;
  tmp.known_any = slot.knownAny() ? 0xF : 0;
  Node& m = stored != nullptr ? *stored : tmp;
  const double ds = update(m);
  slot.setKnown(m.known_all == 0xF, m.known_any != 0);
  if (slot.impl().isTrivial(m)) {
    if (stored != nullptr) slot.remove();
  } else if (stored == nullptr) {
    slot.install(m);
  }
  return ds;
}

/// A stored coefficient (a detail or a block average) as an update writes it: within
/// +-kMaxStoredLogOdds, the bound of a map file (limits.h), so that every map saves a file that
/// loads. A loaded file may hold cells far beyond the bound (its average plus up to three details
/// per level, each at the bound), and the details an update derives from them would not be
/// (issue 42: -1.1e30 after one scan); saturated, such a node's children keep their mean and
/// share what is left. Maps made by scans never come near it (|odd| <= 50 per scan).
inline double keepStored(double v) {
  // x > y ? x : y and x < y ? x : y are one maxsd and one minsd (std::max / std::min keep their
  // first operand on ties and NaN: compares and blends). foldChanges so takes 42 instructions a
  // call, 57 with std::min / std::max in a loop, 32 without the bound (callgrind, GCC 12 -O3).
  const double up = v > -kMaxStoredLogOdds ? v : -kMaxStoredLogOdds;
  return up < kMaxStoredLogOdds ? up : kMaxStoredLogOdds;
}

/// Folds the changes of the averages of n's four children into n's details (one forward Haar
/// step, each kept by keepStored()); returns the change of n's average.
inline double foldChanges(Node& n, const std::array<double, 4>& delta) {
  haar::Details<double> dd;
  const double ds = haar::forward(delta, &dd);
  const double d0 = keepStored(n.d[0] + dd[0]), d1 = keepStored(n.d[1] + dd[1]);
  const double d2 = keepStored(n.d[2] + dd[2]);
  n.d[0] = d0;
  n.d[1] = d1;
  n.d[2] = d2;
  return ds;
}

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_UPDATE_MAP_SLOT_H_
