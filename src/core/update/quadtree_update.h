// The quadtree update of one scan (ALGORITHM.md sections 3 and 6): Integrator<P> walks a block
// coarse to fine against the ScanClassifier's classes. U is skipped, E is applied at the slot's
// own scale (a lazy tag with forgetting), the rest descends; the children's average changes fold
// into the parent's details with one forward Haar step. With kNdt (MapParams::ndt and "forget")
// the walk also carries the span of the block's Gaussians under each square and forgets those the
// scan observes (ndt_update.h); with kHits (MapParams::reflection) it lists the occupied cells
// for the reflection map (reflection_update.h). Not installed; included only by
// src/core/integrate*.cpp.
#ifndef WAVOG_MAPPING_SRC_CORE_UPDATE_QUADTREE_UPDATE_H_
#define WAVOG_MAPPING_SRC_CORE_UPDATE_QUADTREE_UPDATE_H_

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <vector>

#include "classify/scan_classifier.h"
#include "payloads/ndt_update.h"
#include "payloads/reflection_update.h"
#include "update/map_slot.h"
#include "update/split_plan.h"
#include "update/tile_update.h"
#include "update/update_policy.h"
#include "wavog_mapping/core/haar.h"

namespace wavog {
namespace detail {

/// The spans of a node's four children: without Gaussians, nothing (every child reads the empty
/// span), so that the walk without them is the walk it always was.
struct NoSpans {
  const NdtSpan& operator[](std::size_t) const {
    static const NdtSpan kNone{};
    return kNone;
  }
};

template <PolicyType P, bool kNdt = false, bool kHits = false>
class Integrator {
  using Spans = std::conditional_t<kNdt, std::array<NdtSpan, 4>, NoSpans>;

 public:
  /// Node groups come from and go to `store` (one Integrator per thread); with kNdt, the
  /// Gaussians' forgetting goes to `ndt`; with kHits, the occupied cells go to `hits`.
  Integrator(WaveletMap::Impl& impl, NodeStore& store, const ScanClassifier& classifier,
             const PolicyConsts& pc, NdtBlockUpdate* ndt = nullptr, HitBlockUpdate* hits = nullptr)
      : impl_(impl),
        store_(store),
        cls_(classifier),
        pc_(pc),
        lazy_(impl.params.lazy_forgetting),
        ndt_(ndt),
        observed_(hits != nullptr ? hits->observations() : nullptr) {}

  /// Tree nodes and finest cells visited so far.
  std::uint64_t visited() const { return visited_; }

  /// Updates block `b` (origin cell ix0, iy0) classified as `box`; with kNdt, `sp` spans its
  /// Gaussians.
  void integrateBlock(Block& b, std::int64_t ix0, std::int64_t iy0, const SquareInfo& box,
                      const NdtSpan& sp = NdtSpan{}) {
    RootSlot slot(impl_, store_, b);
    const double s = b.s;
    if constexpr (kNdt) enterSlot(sp, box);
    if constexpr (kHits) enterCells(0);
    const double ds = updateSlot(
        slot, box.cls, s, [&](Node& m) { return visitNode(m, box, impl_.levels, ix0, iy0, s); });
    b.s = keepStored(b.s + ds);
  }

  // The walk of blocks split below their roots (split_plan.h), without payloads.

  /// Step 1 (calling thread; node groups from the block's spares): updates the top `split`
  /// levels of block b (origin ix0, iy0, classified as `box`) as integrateBlock() would, except
  /// that the slots `split` levels below the root that must be refined become parts, and every
  /// refined slot above them waits in `plan` for its children's changes.
  void planBlock(Block& b, std::int64_t ix0, std::int64_t iy0, const SquareInfo& box, int split,
                 SplitPlan* plan) {
    static_assert(!kNdt && !kHits, "the split walk carries no payloads");
    RootSlot slot(impl_, store_, b);
    const double s = b.s;
    const double ds = updateSlotWith(slot, box.cls, s, [&](Node* stored) {
      Node& m = stored != nullptr ? *stored : storeUniform(slot);
      planNode(m, box, impl_.levels, ix0, iy0, s, split, 0, &b, nullptr, 0, -1, plan);
      return 0.0;  // settle() adds the change
    });
    b.s = keepStored(b.s + ds);
  }

  /// Step 2 (any thread): updates part t (node groups from its own spares).
  void visitPart(SplitTask* t) {
    store_.useSpare(t->spare);
    t->ds = visitNode(*t->node, t->box, t->level, t->ix0, t->iy0, t->s);
  }

  /// Step 3 (calling thread): children before parents, each waiting slot's changes fold into its
  /// node (a frame) and the slot is settled as refineSlot() settles it.
  void settle(SplitPlan* plan) {
    Block* current = nullptr;
    for (std::size_t i = plan->tasks.size(); i-- > 0;) {
      SplitTask& t = plan->tasks[i];
      if (t.block != current) {
        current = t.block;
        store_.useSpare(&current->spare);
      }
      if (!t.part) t.ds = foldChanges(*t.node, t.delta);
      if (t.parent == nullptr) {
        RootSlot slot(impl_, store_, *t.block);
        settleSlot(slot, *t.node);
        t.block->s = keepStored(t.block->s + t.ds);
      } else {
        ChildSlot slot(impl_, store_, *t.parent, t.q);
        settleSlot(slot, *t.node);
        plan->tasks[static_cast<std::size_t>(t.up)].delta[static_cast<std::size_t>(t.q)] += t.ds;
      }
    }
  }

 private:
  // The rules of one slot of class `cls` whose average is s (U skipped, E at the slot's own
  // scale, the section 3.4 skip); descend(m) updates the slot's node m (the stored one, or a
  // temporary uniform one) when the slot must be refined, and returns the change of its average.
  // With kNdt, slot_span_ spans the Gaussians under the slot and slot_box_ is a square
  // classification holding it (for its cells' classes), set by enterSlot(). Returns the change of
  // the slot's average.
  template <typename Slot, typename Descend>
  [[gnu::always_inline]] double updateSlot(Slot& slot, CellClass cls, double s, Descend descend) {
    return updateSlotWith(slot, cls, s,
                          [&](Node* node) { return refineSlot(slot, node, descend); });
  }
  // updateSlot() whose refinement is refine(slot's stored node or nullptr): refineSlot() in the
  // walk, a plan of the slot's update in the split walk.
  template <typename Slot, typename Refine>
  [[gnu::always_inline]] double updateSlotWith(Slot& slot, CellClass cls, double s,
                                               Refine refine) {
    Node* node = slot.node();
    switch (cls) {
      case CellClass::kUnknown:
        return 0.0;
      case CellClass::kEmpty:
        if (node == nullptr) {  // uniform block: exact for every policy
          if constexpr (kNdt) forgetSlot();
          slot.setKnown(true, true);
          return applyPolicy<P>(pc_, CellClass::kEmpty, s) - s;
        }
        if (kAffineEmpty<P> && node->known_all == 0xF) {
          if constexpr (kNdt) forgetSlot();
          if constexpr (P == PolicyType::kForget) forgetSubtree(slot, node);
          slot.setKnown(true, true);
          return applyPolicy<P>(pc_, CellClass::kEmpty, s) - s;
        }
        break;  // detail below (non-affine policy) or knowledge still to record: descend
      case CellClass::kFreeOrUnknown:
        // ALGORITHM.md 3.4: the E part would not change a uniform, fully known block.
        if (node == nullptr && slot.knownAll() &&
            std::fabs(applyPolicy<P>(pc_, CellClass::kEmpty, s) - s) <= pc_.unchanged_tol) {
          if constexpr (kNdt) {
            if (!slot_span_.empty()) ndt_->forgetObserved(slot_span_, *slot_box_);
          }
          return 0.0;
        }
        break;
      default:
        break;
    }
    return refine(node);
  }

  // The split walk's visitNode(): node m (level l, average s) of a slot to refine, `left` levels
  // above the parts; `part` numbers the slot among the block's parts so far (2 bits per level);
  // the slot is the root of b (parent nullptr) or child q of *parent, whose task is `up`.
  void planNode(Node& m, const SquareInfo& box, int l, std::int64_t ix0, std::int64_t iy0,
                double s, int left, std::size_t part, Block* b, Node* parent, int q, long up,
                SplitPlan* plan) {
    const auto self = static_cast<long>(plan->tasks.size());
    SplitTask t;
    t.block = b;
    t.parent = parent;
    t.q = q;
    t.node = &m;
    t.up = up;
    if (left == 0) {
      t.part = true;
      t.box = box;
      t.level = l;
      t.ix0 = ix0;
      t.iy0 = iy0;
      t.s = s;
      t.spare = &b->part_spare[part];
      plan->tasks.push_back(t);
      plan->parts.push_back(static_cast<std::size_t>(self));
      return;
    }
    plan->tasks.push_back(t);
    ++visited_;
    impl_.flush(m);
    const std::array<double, 4> c = haar::backward(s, m.d);
    std::array<double, 4> delta{};
    const std::int64_t half = std::int64_t{1} << (l - 1);
    for (int cq = 0; cq < 4; ++cq) {
      const auto qu = static_cast<std::size_t>(cq);
      const std::int64_t cx = ix0 + ((cq & 1) ? half : 0), cy = iy0 + ((cq & 2) ? half : 0);
      const SquareInfo child_box = cls_.classifySquare(l - 1, cx, cy, box);
      ++visited_;
      if (child_box.cls == CellClass::kUnknown) continue;
      ChildSlot slot(impl_, store_, m, cq);
      delta[qu] = updateSlotWith(slot, child_box.cls, c[qu], [&](Node* stored) {
        Node& cm = stored != nullptr ? *stored : storeUniform(slot);
        planNode(cm, child_box, l - 1, cx, cy, c[qu], left - 1, part * 4 + qu, b, &m, cq, self,
                 plan);
        return 0.0;  // settle() adds the change
      });
    }
    plan->tasks[static_cast<std::size_t>(self)].delta = delta;
  }

  // Stores a uniform node with the knowledge of `slot` (the temporary of refineSlot) in it.
  template <typename Slot>
  Node& storeUniform(Slot& slot) {
    Node tmp{};
    tmp.known_all = slot.knownAll() ? 0xF : 0;
    tmp.known_any = slot.knownAny() ? 0xF : 0;
    slot.install(tmp);
    return *slot.node();
  }

  // refineSlot()'s end for a stored node m: the slot takes m's knowledge; a trivial m goes.
  template <typename Slot>
  void settleSlot(Slot& slot, const Node& m) {
    slot.setKnown(m.known_all == 0xF, m.known_any != 0);
    if (impl_.isTrivial(m)) slot.remove();
  }

  // kNdt: the next slot to update spans `sp`, inside the square classified as `box`.
  void enterSlot(const NdtSpan& sp, const SquareInfo& box) {
    slot_span_ = sp;
    slot_box_ = &box;
  }
  // kHits: the first cell of the next slot to update has code `code`.
  void enterCells(std::uint32_t code) { slot_code_ = code; }
  // kNdt: the scan observes every cell of the slot.
  void forgetSlot() {
    slot_span_.forEach([this](NdtEntry* x) { ndt_->forget(x); });
  }

  // The multiplicative part of an E update of a fully known subtree with forgetting: a lazy tag
  // (ALGORITHM.md 6.3; the additive part reaches the parent through the average), or eagerly.
  template <typename Slot>
  void forgetSubtree(Slot& slot, Node* node) {
    if (!lazy_) {
      scaleSubtree(*node);
      return;
    }
    if (pc_.units > impl_.k_cap) {
      // One scan beyond what a tag counts (a fine unit, forget_half_life): negligible at once,
      // else applied eagerly (stored details scale by a whatever tags they carry).
      if (pc_.units >= impl_.k_star) {
        slot.remove();
      } else {
        scaleSubtree(*node);
      }
      return;
    }
    impl_.addPending(*node, static_cast<unsigned>(pc_.units));
    if (node->k >= impl_.k_star) slot.remove();  // section 6.5: subtree negligible
  }

  // Descends through node n (level l, average s): flushes its tag (F1), updates its 4 children,
  // folds their average changes into n's details with one forward Haar step.
  double visitNode(Node& n, const SquareInfo& box, int l, std::int64_t ix0, std::int64_t iy0,
                   double s) {
    [[maybe_unused]] const std::uint32_t code = slot_code_;  // kHits: its first cell
    ++visited_;
    impl_.flush(n);
    // The children are read after the (long) classification: fetch them meanwhile.
    if (l == impl_.tile_level) return visitTile(n, box, ix0, iy0, s);
    if (n.children != 0) impl_.pool.prefetch(n.children);
    const std::array<double, 4> c = haar::backward(s, n.d);
    std::array<double, 4> delta{};
    Spans parts{};
    if constexpr (kNdt) slot_span_.split(l, parts.data());
    const std::int64_t half = std::int64_t{1} << (l - 1);
    for (int q = 0; q < 4; ++q) {
      const auto qu = static_cast<std::size_t>(q);
      const std::int64_t cx = ix0 + ((q & 1) ? half : 0), cy = iy0 + ((q & 2) ? half : 0);
      const SquareInfo child_box = cls_.classifySquare(l - 1, cx, cy, box);
      ++visited_;
      if (child_box.cls == CellClass::kUnknown) continue;
      ChildSlot slot(impl_, store_, n, q);
      if constexpr (kNdt) enterSlot(parts[qu], child_box);
      if constexpr (kHits) {
        enterCells(code + (static_cast<std::uint32_t>(q) << (2 * (l - 1))));
      }
      delta[qu] = updateSlot(slot, child_box.cls, c[qu], [&](Node& m) {
        return visitNode(m, child_box, l - 1, cx, cy, c[qu]);
      });
    }
    return foldChanges(n, delta);
  }

  // A tile node n (tag flushed; storage/tile.h), average s, cells classified together
  // (classifyTileCells): the policy applied to its E and O cells, its Gaussians of observed cells
  // forgotten (kNdt), its O cells listed (kHits); the tile made if n had none, freed if it became
  // uniform. Returns the change of n's average.
  [[gnu::noinline]] double visitTile(Node& n, const SquareInfo& box, std::int64_t ix0,
                                     std::int64_t iy0, double s) {
    const int t = impl_.tile_level;
    const TileMasks cells = cls_.classifyTileCells(t, ix0, iy0, box);
    const std::uint64_t observed = cells.e | cells.o;
    visited_ += cellCount(observed);
    if constexpr (kNdt) {
      slot_span_.forEach([&](NdtEntry* x) {
        if ((observed >> kTileMorton.cell[x->code & 63u]) & 1u) ndt_->forget(x);
      });
    }
    if (observed == 0) return 0.0;
    if (!WaveletMap::Impl::hasTile(n)) impl_.addTile(store_, n);
    const double ds = impl_.withTile(n, [&](auto& tile) {
      // A cell's value is s + (v - base): stored value minus `offset`.
      const double offset = tile.base - s;
      if constexpr (kHits) {
        for (std::uint64_t m = cells.o; m != 0; m &= m - 1) {
          const auto i = static_cast<unsigned>(__builtin_ctzll(m));
          observed_->push_back({slot_code_ + kTileMorton.code[i], tile.v[i] - offset});
        }
      }
      const double sum = updateTileCells<P>(shiftPolicy<P>(pc_, offset), &tile, cells.e, cells.o);
      tile.known |= observed;
      // The cells' mean moved by the change: so does base, and the unobserved cells keep their
      // stored values.
      const double change = sum / static_cast<double>(std::uint64_t{1} << (2 * t));
      tile.base = keepStored(tile.base + change);
      return change;
    });
    impl_.dropTileIfUniform(store_, n);
    return ds;
  }

  // Eager forgetting (lazy tags off): every detail of the subtree times a, now.
  void scaleSubtree(Node& n) {
    ++visited_;
    for (double& d : n.d) d *= pc_.a;
    if (WaveletMap::Impl::hasTile(n)) {
      visited_ += std::uint64_t{1} << (2 * impl_.tile_level);  // its cells
      impl_.withTile(n, [this](auto& t) { scaleTile(&t, pc_.a); });
      return;
    }
    if (n.children == 0) return;
    for (int q = 0; q < 4; ++q) {
      if (impl_.hasChild(n, q)) scaleSubtree(impl_.child(n, q));
    }
  }

  WaveletMap::Impl& impl_;
  NodeStore& store_;
  const ScanClassifier& cls_;
  const PolicyConsts pc_;
  const bool lazy_;
  NdtBlockUpdate* const ndt_;
  std::vector<HitObservation>* const observed_;
  // kNdt: the Gaussians under the slot being updated and a classification holding them. A
  // visit reads them on entry (children set them again, one after the other).
  NdtSpan slot_span_;
  const SquareInfo* slot_box_ = nullptr;
  // kHits: the first cell of the slot being updated.
  std::uint32_t slot_code_ = 0;
  std::uint64_t visited_ = 0;
};

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_UPDATE_QUADTREE_UPDATE_H_
