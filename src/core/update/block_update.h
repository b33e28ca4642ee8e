// The update of one scan's blocks (integrate.cpp): the list of blocks a scan touches and the loop
// that takes them one by one (from a counter shared by the threads of the scan) through the
// quadtree update Integrator<P, kNdt, kHits> and, with MapParams::ndt, the update of their
// Gaussians, with MapParams::reflection (kHits), that of their hits.
// Not installed; included only by src/core/update/integrate*.cpp.
#ifndef WAVOG_MAPPING_SRC_CORE_UPDATE_BLOCK_UPDATE_H_
#define WAVOG_MAPPING_SRC_CORE_UPDATE_BLOCK_UPDATE_H_

#include <atomic>
#include <cstdint>
#include <vector>

#include "storage/map_impl.h"
#include "payloads/ndt_update.h"
#include "update/quadtree_update.h"
#include "update/split_plan.h"
#include "payloads/reflection_update.h"

namespace wavog {
namespace detail {

// One block of the scan: its storage, origin cell and class, and its end-points (MapParams::ndt).
struct BlockJob {
  Block* block;
  std::int64_t ix0, iy0;
  SquareInfo box;
  const NdtPoint *points = nullptr, *points_end = nullptr;
};

// Updates the blocks jobs[i] for the indices i taken from `next` (shared by the threads of one
// scan); node groups from `store`; with `ndt`, their Gaussians too (the walk finds the observed
// ones when the policy forgets them: kNdt); with kHits, their hits by `hits`. Returns the nodes
// visited. The one place Integrator is made, so the hot code is compiled once per policy (and
// once more with the Gaussians, and with the hits).
template <PolicyType P, bool kNdt, bool kHits = false>
[[gnu::noinline]] std::uint64_t updateBlocks(WaveletMap::Impl& impl, NodeStore& store,
                                             const ScanClassifier& cls, const PolicyConsts& pc,
                                             const NdtConsts* ndt, const HitConsts* hits,
                                             const std::vector<BlockJob>& jobs,
                                             std::atomic<std::size_t>* next) {
  NdtBlockUpdate ndt_update(cls, ndt != nullptr ? *ndt : NdtConsts{});
  HitBlockUpdate hit_update(impl, hits != nullptr ? *hits : HitConsts{});
  Integrator<P, kNdt, kHits> integrator(impl, store, cls, pc, &ndt_update, &hit_update);
  for (std::size_t i = next->fetch_add(1, std::memory_order_relaxed); i < jobs.size();
       i = next->fetch_add(1, std::memory_order_relaxed)) {
    const BlockJob& j = jobs[i];
    store.useSpare(&j.block->spare);
    const bool with_ndt = ndt != nullptr && j.block->ndt;
    const NdtSpan ndt_span =
        with_ndt ? ndt_update.begin(*j.block->ndt, j.ix0, j.iy0, j.points, j.points_end)
                 : NdtSpan{};
    if constexpr (kNdt) {
      integrator.integrateBlock(*j.block, j.ix0, j.iy0, j.box, ndt_span);
    } else {
      integrator.integrateBlock(*j.block, j.ix0, j.iy0, j.box);
    }
    if (with_ndt) ndt_update.finish();
    if constexpr (kHits) hit_update.finish(*j.block, j.ix0, j.iy0);
  }
  return integrator.visited();
}

// The split walk (split_plan.h), one step per function so that each thread's part of the work
// is the hot code of its own: planBlocks() (calling thread) walks the top levels of every block
// of `jobs` into `plan`; updateParts() (every thread) updates the parts whose indices (in
// plan->parts) it takes from `next`; settleBlocks() (calling thread) folds and settles. Each
// returns the nodes it visited. The blocks' spare groups go to their parts between the first two.
template <PolicyType P>
[[gnu::noinline]] std::uint64_t planBlocks(WaveletMap::Impl& impl, NodeStore& store,
                                           const ScanClassifier& cls, const PolicyConsts& pc,
                                           const std::vector<BlockJob>& jobs, int split,
                                           SplitPlan* plan) {
  Integrator<P> integrator(impl, store, cls, pc);
  for (const BlockJob& j : jobs) {
    store.useSpare(&j.block->spare);
    integrator.planBlock(*j.block, j.ix0, j.iy0, j.box, split, plan);
  }
  return integrator.visited();
}

template <PolicyType P>
[[gnu::noinline]] std::uint64_t updateParts(WaveletMap::Impl& impl, NodeStore& store,
                                            const ScanClassifier& cls, const PolicyConsts& pc,
                                            SplitPlan* plan, std::atomic<std::size_t>* next) {
  Integrator<P> integrator(impl, store, cls, pc);
  const std::size_t n = plan->parts.size();
  for (std::size_t i = next->fetch_add(1, std::memory_order_relaxed); i < n;
       i = next->fetch_add(1, std::memory_order_relaxed)) {
    SplitTask& t = plan->tasks[plan->parts[i]];
    const std::uint64_t before = integrator.visited();
    integrator.visitPart(&t);
    t.visits = integrator.visited() - before;
  }
  return integrator.visited();
}

template <PolicyType P>
[[gnu::noinline]] void settleBlocks(WaveletMap::Impl& impl, NodeStore& store,
                                    const ScanClassifier& cls, const PolicyConsts& pc,
                                    SplitPlan* plan) {
  Integrator<P> integrator(impl, store, cls, pc);
  integrator.settle(plan);
}

/// Gives the spare groups of each block of the plan to its parts of this scan, one by one in
/// turn (the parts of a block are consecutive in plan->parts), so that groups a block freed
/// above its parts are used again below them.
inline void lendSparesToParts(WaveletMap::Impl& impl, SplitPlan* plan) {
  const std::size_t n = plan->parts.size();
  for (std::size_t first = 0; first < n;) {
    Block* b = plan->tasks[plan->parts[first]].block;
    std::size_t end = first + 1;
    while (end < n && plan->tasks[plan->parts[end]].block == b) ++end;
    for (std::size_t i = first; b->spare.groups != 0; i = i + 1 < end ? i + 1 : first) {
      impl.pool.pushSpare(&plan->tasks[plan->parts[i]].spare->groups,
                          impl.pool.popSpare(&b->spare.groups));
    }
    for (std::size_t i = first; b->spare.tiles != 0; i = i + 1 < end ? i + 1 : first) {
      impl.tiles.pushSpare(&plan->tasks[plan->parts[i]].spare->tiles,
                           impl.tiles.popSpare(&b->spare.tiles));
    }
    first = end;
  }
}

// The instantiations compiled apart from integrate.cpp (integrate_ndt.cpp,
// integrate_reflection.cpp), so that they do not change how the compiler inlines the others:
// WAVOG_UPDATE_BLOCKS(policy, kNdt, kHits) for each.
#define WAVOG_UPDATE_BLOCKS_ALL                             \
  WAVOG_UPDATE_BLOCKS(PolicyType::kForget, true, false)     \
  WAVOG_UPDATE_BLOCKS(PolicyType::kNone, false, true)       \
  WAVOG_UPDATE_BLOCKS(PolicyType::kMax, false, true)        \
  WAVOG_UPDATE_BLOCKS(PolicyType::kClamp, false, true)      \
  WAVOG_UPDATE_BLOCKS(PolicyType::kForget, false, true)     \
  WAVOG_UPDATE_BLOCKS(PolicyType::kClampLower, false, true) \
  WAVOG_UPDATE_BLOCKS(PolicyType::kClampUpper, false, true) \
  WAVOG_UPDATE_BLOCKS(PolicyType::kForget, true, true)

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_UPDATE_BLOCK_UPDATE_H_
