// WaveletMap::integrate: one scan into the map (ALGORITHM.md sections 3 and 6). The scan is
// prepared and classified by the ScanClassifier (scan_classifier.h); every block within its
// reach that is not U goes through the quadtree update Integrator<P> (quadtree_update.h), one
// instantiation per update policy. The touched blocks are found and created first, on the calling
// thread; with num_threads != 1 they are then updated on the map's worker threads. A scan of few
// blocks (indoors) has its blocks split below their roots, so that the threads share the parts
// of one block (split_plan.h).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <thread>
#include <utility>
#include <vector>

#include "update/block_update.h"
#include "storage/map_impl.h"
#include "classify/scan_classifier.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog {
namespace detail {
// The update with the Gaussians' forgetting is compiled in its own file (integrate_ndt.cpp), so
// that it does not change how the compiler inlines the others.
// So are the updates with the hits of the reflection map (integrate_reflection.cpp).
#define WAVOG_UPDATE_BLOCKS(P, NDT, HITS)                                                          \
  extern template std::uint64_t updateBlocks<P, NDT, HITS>(                                        \
      WaveletMap::Impl&, NodeStore&, const ScanClassifier&, const PolicyConsts&, const NdtConsts*, \
      const HitConsts*, const std::vector<BlockJob>&, std::atomic<std::size_t>*);
WAVOG_UPDATE_BLOCKS_ALL
#undef WAVOG_UPDATE_BLOCKS
}  // namespace detail

namespace {

using detail::ScanClassifier;

// Numerical floor of the "E update changes nothing" test (log-odds).
constexpr double kUnchangedFloor = 1e-9;

// Box of finest cells [min, max) holding every cell within `reach` (m) of (px, py). prepare()
// refuses a scan whose pose plus reach leaves the extent (limits.h), so the casts are exact.
CellBox reachBox(double px, double py, double reach, double res) {
  CellBox box;
  box.min_x = static_cast<std::int64_t>(std::floor((px - reach) / res));
  box.min_y = static_cast<std::int64_t>(std::floor((py - reach) / res));
  box.max_x = static_cast<std::int64_t>(std::floor((px + reach) / res)) + 1;
  box.max_y = static_cast<std::int64_t>(std::floor((py + reach) / res)) + 1;
  return box;
}

// The blocks of `impl`'s region (MapParams::region) within `reach` (m) of the sensor: the blocks
// the scan may change there; empty when it reaches none of them.
CellBox regionBlocks(const WaveletMap::Impl& impl, const detail::PreparedScan& ps) {
  const double block_size = static_cast<double>(std::int64_t{1} << impl.levels) * ps.res;
  CellBox b = reachBox(ps.px, ps.py, ps.reach, block_size);
  const BlockRegion& r = impl.params.region;
  if (r.all) return b;
  b.min_x = std::max(b.min_x, r.min_bx);
  b.min_y = std::max(b.min_y, r.min_by);
  b.max_x = std::min(b.max_x, r.max_bx);
  b.max_y = std::min(b.max_y, r.max_by);
  return b;
}

// A region shard's test before the scan's preparation (which costs 10-15 % of integrating an
// indoor scan): true only when the scan is certainly one the core takes (the checks of
// prepared_scan.cpp: geometry, pose, extent, a valid beam) and certainly reaches no block of the
// region, by a bound on its reach that is never below the prepared one (the largest U limit over
// the valid beams: a return's z + half band, a no-return's clear distance). Any doubt: false, and
// the scan is prepared, refused or tested exactly as in a map of every block.
bool surelyOutsideRegion(const MapParams& p, const Pose2& pose, const ScanView& scan) {
  if (detail::checkScan(pose, scan) != ScanStatus::kOk) return false;
  const detail::BeamLimits limits = detail::beamLimits(p, scan);
  if (!detail::reachInExtent(pose, limits, p.grid.resolution)) return false;
  const double sensor_max = limits.sensor_max;
  const double clear = limits.clear;
  const double half_band = limits.half_band;
  // The farthest a valid beam reaches, and whether there is one (returns: finite, > 0, at least
  // range_min and below sensor_max; no-returns: at or beyond sensor_max, valid when clear > 0).
  double far = 0.0;
  bool valid = false;
  const float* r = scan.ranges;
  for (std::size_t j = 0; j < scan.count; ++j) {
    const double z = r[j];
    if (!(z > 0.0) || z < scan.range_min) continue;  // NaN, -inf, <= 0, below range_min
    if (z < sensor_max) {
      valid = true;
      far = std::max(far, z);
    } else if (clear > 0) {
      valid = true;
    }
  }
  if (!valid) return false;
  double reach = std::max(far + half_band, clear);
  reach += 1e-9 * (reach + 1.0);  // round-off margin: never below the prepared reach
  const double block = static_cast<double>(std::int64_t{1} << p.grid.block_levels) * p.grid.resolution;
  const CellBox b = reachBox(pose.x, pose.y, reach, block);
  const BlockRegion& g = p.region;
  return b.max_x <= g.min_bx || b.min_x >= g.max_bx || b.max_y <= g.min_by || b.min_y >= g.max_by;
}

// The NDT policy of one scan (params.h, MapParams::ndt): forgetting by the scan's rate, the
// clamp policies' weight cap, sums otherwise. ndt_min_weight counts end-points: the floor is
// that many of this scan's end-points (each weighing g under "forget", 1 otherwise), so that an
// end-point always makes a Gaussian when ndt_min_weight <= 1 (issue 38).
detail::NdtConsts ndtConsts(const MapParams& p, double a, double g) {
  detail::NdtConsts c;
  if (p.policy.type == PolicyType::kForget) {
    c.a = a;
    c.g = g;
  } else if (p.policy.type == PolicyType::kClamp || p.policy.type == PolicyType::kClampUpper) {
    c.cap = p.ndt_max_weight;
  }
  c.min_weight = p.ndt_min_weight * c.g;
  return c;
}

// Node groups one block can take in one scan at most: a group per node of levels 2..L (a
// block's live and spare groups never exceed that, and fresh ones are taken only when its
// spares are used up).
std::size_t maxGroupsPerBlock(int levels) {
  return ((std::size_t{1} << (2 * (levels - 1))) - 1) / 3;
}

// Participants of parallel integrations: num_threads, 0 meaning every core.
int threadsFor(const MapParams& p) {
  if (p.num_threads != 0) return p.num_threads;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

// Puts the blocks that are likely the most work first, so that the threads of a parallel
// integration finish together instead of one of them starting a heavy block last: blocks that may
// hold hits (kMixed) before free or partly unknown ones, nearer the sensor (more beams, more
// cells of the fan) before farther. Only the order of the work changes, not its result.
void orderByWork(const detail::PreparedScan& ps, double block_size,
                 std::vector<detail::BlockJob>* jobs) {
  const auto cost_rank = [&](const detail::BlockJob& j) {
    const double res = ps.res;
    const double cx = (static_cast<double>(j.ix0) * res + 0.5 * block_size) - ps.px;
    const double cy = (static_cast<double>(j.iy0) * res + 0.5 * block_size) - ps.py;
    return std::make_pair(j.box.cls == CellClass::kMixed ? 0 : 1, cx * cx + cy * cy);
  };
  std::stable_sort(jobs->begin(), jobs->end(),
                   [&](const detail::BlockJob& a, const detail::BlockJob& b) {
                     return cost_rank(a) < cost_rank(b);
                   });
}

template <PolicyType P>
std::uint64_t updateBlocksFor(WaveletMap::Impl& impl, detail::NodeStore& store,
                              const ScanClassifier& cls, const detail::PolicyConsts& pc,
                              const detail::NdtConsts* ndt, const detail::HitConsts* hits,
                              const std::vector<detail::BlockJob>& jobs,
                              std::atomic<std::size_t>* next) {
  // The Gaussians: "forget" is the one policy whose observations change them.
  if constexpr (P == PolicyType::kForget) {
    if (ndt != nullptr && ndt->forgets()) {
      if (hits != nullptr) {
        return detail::updateBlocks<P, true, true>(impl, store, cls, pc, ndt, hits, jobs, next);
      }
      return detail::updateBlocks<P, true>(impl, store, cls, pc, ndt, hits, jobs, next);
    }
  }
  if (hits != nullptr) {
    return detail::updateBlocks<P, false, true>(impl, store, cls, pc, ndt, hits, jobs, next);
  }
  return detail::updateBlocks<P, false>(impl, store, cls, pc, ndt, hits, jobs, next);
}

// The worker threads of a map of parameters `p` (made on first use, or again when num_threads
// changed); nullptr when it integrates on the calling thread alone (no pool is made).
detail::WorkerPool* poolFor(const MapParams& p, std::unique_ptr<detail::WorkerPool>* workers) {
  const int threads = threadsFor(p);
  if (threads <= 1) return nullptr;
  if (!*workers || (*workers)->threads() != threads) {
    *workers = std::make_unique<detail::WorkerPool>(threads);
  }
  return workers->get();
}

// The worker threads of `impl` for a scan that has `jobs` pieces of work (poolFor), and how many
// of them take part; 1 means the calling thread alone.
int workersFor(const WaveletMap::Impl& impl, std::size_t jobs,
               std::unique_ptr<detail::WorkerPool>* workers) {
  const int threads = std::min(threadsFor(impl.params), static_cast<int>(jobs));
  if (threads <= 1) return 1;
  poolFor(impl.params, workers);
  return threads;
}

// Runs work(store) on `threads` of the workers, each with a NodeStore counting into its own tally
// (visits and node / group count changes, modulo 2^64, on their own cache lines), added to the
// map's afterwards; work returns the nodes it visited. Returns the visits of all.
template <typename Work>
std::uint64_t runOnWorkers(WaveletMap::Impl& impl, detail::WorkerPool& workers, int threads,
                           Work work) {
  struct alignas(64) Tally {
    std::uint64_t visited = 0;
    detail::StoreCounts counts;
  };
  std::vector<Tally> tallies(static_cast<std::size_t>(workers.threads()));
  const auto active = static_cast<std::size_t>(threads);
  workers.run([&](int t) {
    const auto tu = static_cast<std::size_t>(t);
    if (tu >= active) return;
    Tally& tally = tallies[tu];
    detail::NodeStore store(impl.pool, impl.tiles, nullptr, &tally.counts);
    tally.visited = work(store);
  });
  std::uint64_t visited = 0;
  for (const Tally& tally : tallies) {
    visited += tally.visited;
    impl.counts.nodes += tally.counts.nodes;
    impl.counts.groups += tally.counts.groups;
    impl.counts.tiles += tally.counts.tiles;
  }
  return visited;
}

// Puts the parts of `plan` in the order the threads take them: the costliest first, so that no
// thread starts a large part last. A part's cost is predicted by its visits in the last parallel
// scan of this thread's plan (the same part of the same block: its spare list), the mean of
// those for a part not in it; equal predictions (the first scan) go as orderByWork() puts
// blocks. The greedy 2-thread makespan of the parts (fr079 at 5 cm, their time by rdtsc, min
// over 5 repetitions) is 0.533 of their work nearest first, 0.516 in this order, 0.512 by the
// time itself (visits and time correlate at 0.94). Only the order of the work changes.
void orderParts(const detail::PreparedScan& ps, detail::SplitPlan* plan) {
  struct Key {
    double cost;
    int unmixed;
    double d2;
    std::size_t part;
    bool operator<(const Key& o) const {
      if (cost != o.cost) return cost > o.cost;
      if (unmixed != o.unmixed) return unmixed < o.unmixed;
      if (d2 != o.d2) return d2 < o.d2;
      return part < o.part;
    }
  };
  thread_local std::vector<Key> keys;  // reused from scan to scan
  keys.clear();
  double known_sum = 0.0;
  std::size_t known = 0;
  const auto& last = plan->last_visits;
  for (const std::size_t i : plan->parts) {
    const detail::SplitTask& t = plan->tasks[i];
    const double half = 0.5 * static_cast<double>(std::int64_t{1} << t.level) * ps.res;
    const double cx = static_cast<double>(t.ix0) * ps.res + half - ps.px;
    const double cy = static_cast<double>(t.iy0) * ps.res + half - ps.py;
    const std::uintptr_t id = reinterpret_cast<std::uintptr_t>(t.spare);
    const auto it =
        std::lower_bound(last.begin(), last.end(), std::make_pair(id, std::uint64_t{0}));
    double cost = -1.0;  // not known yet
    if (it != last.end() && it->first == id) {
      cost = static_cast<double>(it->second);
      known_sum += cost;
      ++known;
    }
    keys.push_back({cost, t.box.cls == CellClass::kMixed ? 0 : 1, cx * cx + cy * cy, i});
  }
  const double mean = known > 0 ? known_sum / static_cast<double>(known) : 0.0;
  for (Key& k : keys) {
    if (k.cost < 0.0) k.cost = mean;
  }
  std::sort(keys.begin(), keys.end());
  for (std::size_t k = 0; k < keys.size(); ++k) plan->parts[k] = keys[k].part;
}

// The blocks of `jobs` split below their roots (split_plan.h): their top levels on this thread,
// their parts on the workers (the costliest first, orderParts), the folding on this thread.
template <PolicyType P>
std::uint64_t integrateSplit(WaveletMap::Impl& impl, const ScanClassifier& cls,
                             const detail::PolicyConsts& pc,
                             const std::vector<detail::BlockJob>& jobs, int split,
                             std::unique_ptr<detail::WorkerPool>* workers) {
  thread_local detail::SplitPlan plan_buffer;  // reused from scan to scan
  detail::SplitPlan& plan = plan_buffer;        // the workers read this thread's copy
  plan.clear();
  detail::NodeStore serial = impl.serialStore();
  std::uint64_t visited = detail::planBlocks<P>(impl, serial, cls, pc, jobs, split, &plan);
  detail::lendSparesToParts(impl, &plan);
  std::atomic<std::size_t> next{0};
  const int threads = workersFor(impl, plan.parts.size(), workers);
  if (threads <= 1) {
    visited += detail::updateParts<P>(impl, serial, cls, pc, &plan, &next);
  } else {
    orderParts(cls.scan(), &plan);
    visited += runOnWorkers(impl, **workers, threads, [&](detail::NodeStore& store) {
      return detail::updateParts<P>(impl, store, cls, pc, &plan, &next);
    });
    plan.last_visits.clear();
    for (const std::size_t i : plan.parts) {
      const detail::SplitTask& t = plan.tasks[i];
      plan.last_visits.emplace_back(reinterpret_cast<std::uintptr_t>(t.spare), t.visits);
    }
    std::sort(plan.last_visits.begin(), plan.last_visits.end());
  }
  detail::settleBlocks<P>(impl, serial, cls, pc, &plan);
  return visited;
}

// `workers`: the map's worker threads (made here on first use), shared by its reflection layers.
template <PolicyType P>
std::uint64_t integrateAll(WaveletMap::Impl& impl, const ScanClassifier& cls, double period,
                           std::unique_ptr<detail::WorkerPool>* workers, IntegrateStats* st) {
  const MapParams& p = impl.params;
  // Forgetting: gamma per scan, or from the scan's period with forget_half_life.
  const std::uint64_t units = impl.scanUnits(period);
  const double a = impl.half_life ? impl.scanFactor(units) : impl.a;
  const double g = impl.half_life ? 1.0 - a : p.policy.gamma;
  const detail::PolicyConsts pc{p.sensor.odd_occ,
                                p.sensor.odd_emp,
                                a,
                                P == PolicyType::kForget ? g : 0.0,
                                p.policy.clamp_min,
                                p.policy.clamp_max,
                                std::max(p.skip_tolerance, kUnchangedFloor),
                                units};
  const detail::PreparedScan& ps = cls.scan();
  const int L = impl.levels;
  const double block_size = static_cast<double>(std::int64_t{1} << L) * ps.res;
  const CellBox blocks = regionBlocks(impl, ps);
  // Serial: classify the blocks and create the touched ones (the hash changes only here, in the
  // same order whatever the thread count, so its iteration order, and the saved file, are too).
  thread_local std::vector<detail::BlockJob> job_buffer;  // reused from scan to scan
  std::vector<detail::BlockJob>& jobs = job_buffer;       // the workers read this thread's copy
  jobs.clear();
  std::uint64_t visited = 0;
  for (std::int64_t by = blocks.min_y; by < blocks.max_y; ++by) {
    for (std::int64_t bx = blocks.min_x; bx < blocks.max_x; ++bx) {
      const std::int64_t ix0 = detail::scaleUp(bx, L), iy0 = detail::scaleUp(by, L);
      const detail::SquareInfo box = cls.classifySquare(L, ix0, iy0);
      ++visited;
      if (box.cls == CellClass::kUnknown) continue;
      jobs.push_back({&impl.getOrCreateBlock(bx, by), ix0, iy0, box});
    }
  }
  // NDT: the scan's end-points by block; a block takes its Gaussians with its first end-point.
  thread_local detail::NdtScanPoints ndt_points;
  detail::NdtConsts ndt_consts;
  const detail::NdtConsts* ndt = nullptr;
  if (p.ndt) {
    ndt_consts = ndtConsts(p, a, g);
    ndt = &ndt_consts;
    ndt_points.build(ps, L);
    for (detail::BlockJob& j : jobs) {
      ndt_points.inBlock(
          detail::blockKey(detail::floorShift(j.ix0, L), detail::floorShift(j.iy0, L)), &j.points,
          &j.points_end);
      if (j.points != j.points_end && !j.block->ndt) {
        j.block->ndt = std::make_unique<detail::NdtCells>();
      }
    }
  }
  // Reflection: the hits of the occupied cells (none to keep under kPrior and kLayers).
  detail::HitConsts hit_consts;
  const detail::HitConsts* hits = nullptr;
  if (impl.reflection_mode == ReflectionMode::kDerived ||
      impl.reflection_mode == ReflectionMode::kCounts) {
    hit_consts.ratios = P == PolicyType::kForget;
    hit_consts.pairs = detail::boundsCounts(P);
    hit_consts.a = a;
    hit_consts.g = g;
    if constexpr (detail::boundsCounts(P)) {
      hit_consts.bound = detail::countBound(p);
      hit_consts.empty_bound = detail::emptyBound(p);
    }
    hit_consts.basis = impl.reflection_basis;
    hits = &hit_consts;
  }
  st->blocks_touched = static_cast<std::uint32_t>(jobs.size());
  // The blocks are independent: each one's update reads only the scan and the parameters and
  // changes only its own nodes, taking node groups from its own spares (NodeStore), so the result
  // does not depend on which thread updates which block, nor in which order.
  // The chunk table grows here, whatever the thread count, so that its size does not depend on it.
  impl.pool.reserveFresh(jobs.size() * maxGroupsPerBlock(L));
  impl.tiles.reserveFresh(jobs.size() * (std::size_t{1} << (2 * (L - impl.tile_level))));
  // Without payloads the blocks of a scan of few blocks are split below their roots, so that
  // threads share a block (split_plan.h); the same whatever the thread count.
  const int split = ndt == nullptr && hits == nullptr && jobs.size() <= detail::kSplitMaxBlocks
                        ? detail::splitLevels(L)
                        : 0;
  if (split > 0) return visited + integrateSplit<P>(impl, cls, pc, jobs, split, workers);
  std::atomic<std::size_t> next{0};
  const int threads = workersFor(impl, jobs.size(), workers);
  if (threads <= 1) {
    detail::NodeStore store = impl.serialStore();
    return visited + updateBlocksFor<P>(impl, store, cls, pc, ndt, hits, jobs, &next);
  }
  orderByWork(ps, block_size, &jobs);
  return visited + runOnWorkers(impl, **workers, threads, [&](detail::NodeStore& store) {
           return updateBlocksFor<P>(impl, store, cls, pc, ndt, hits, jobs, &next);
         });
}

// One instantiation per policy, in the order of PolicyType's enumerators.
using IntegrateFn = std::uint64_t (*)(WaveletMap::Impl&, const ScanClassifier&, double,
                                      std::unique_ptr<detail::WorkerPool>*, IntegrateStats*);
constexpr IntegrateFn kIntegrateFor[] = {
    &integrateAll<PolicyType::kNone>,       &integrateAll<PolicyType::kMax>,
    &integrateAll<PolicyType::kClamp>,      &integrateAll<PolicyType::kForget>,
    &integrateAll<PolicyType::kClampLower>, &integrateAll<PolicyType::kClampUpper>};
static_assert(static_cast<int>(PolicyType::kNone) == 0 &&
                  static_cast<int>(PolicyType::kClampUpper) == 5,
              "kIntegrateFor follows PolicyType's order");

}  // namespace

IntegrateStats WaveletMap::integrate(const Pose2& sensor_pose, const ScanView& scan) {
  IntegrateStats st;
  // Per-thread scratch: its buffers are reused from scan to scan (see the header's
  // thread-safety note).
  if (!impl_->params.region.all && surelyOutsideRegion(impl_->params, sensor_pose, scan)) {
    impl_->nodes_visited_last = 0;
    st.outside_region = true;
    return st;
  }
  thread_local ScanClassifier classifier;
  {
    // The map's threads share the preparation's per-beam work.
    const detail::PrepareHelpers helpers(poolFor(impl_->params, &impl_->workers));
    st.status = classifier.prepare(impl_->params, sensor_pose, scan, &st);
  }
  if (st.status != ScanStatus::kOk) {
    classifier.releaseIfLarge();
    impl_->nodes_visited_last = 0;
    return st;
  }
  const detail::PreparedScan& ps = classifier.scan();
  st.touched = reachBox(ps.px, ps.py, ps.reach, ps.res);
  if (!impl_->params.region.all) {
    // A region shard: a scan that reaches none of its blocks changes nothing here; the walk is
    // not even started (its cost: the preparation above and this test).
    const CellBox in = regionBlocks(*impl_, ps);
    if (in.empty()) {
      classifier.releaseIfLarge();
      impl_->nodes_visited_last = 0;
      st.touched = CellBox{};
      st.outside_region = true;
      return st;
    }
    const int L = impl_->levels;
    st.touched.min_x = std::max(st.touched.min_x, detail::scaleUp(in.min_x, L));
    st.touched.min_y = std::max(st.touched.min_y, detail::scaleUp(in.min_y, L));
    st.touched.max_x = std::min(st.touched.max_x, detail::scaleUp(in.max_x, L));
    st.touched.max_y = std::min(st.touched.max_y, detail::scaleUp(in.max_y, L));
  }
  const auto policy = static_cast<std::size_t>(impl_->params.policy.type);
  st.nodes_visited = kIntegrateFor[policy](*impl_, classifier, scan.period, &impl_->workers, &st);
  // The reflection layers (reflection.cpp; kCounts, kLayers) take the same classification.
  for (WaveletMap* layer : {impl_->hits_layer.get(), impl_->misses_layer.get()}) {
    if (layer == nullptr) continue;
    Impl& l = *layer->impl_;
    IntegrateStats layer_st;
    l.nodes_visited_last = kIntegrateFor[static_cast<std::size_t>(l.params.policy.type)](
        l, classifier, scan.period, &impl_->workers, &layer_st);
  }
  classifier.releaseIfLarge();
  impl_->nodes_visited_last = st.nodes_visited;
  return st;
}

}  // namespace wavog
