// The payload sections of native map files (layout: map_io.cpp): the blocks' normal-distribution
// cells (MapParams::ndt, version 3) and the reflection map's mode, basis and hits
// (MapParams::reflection, version 4; the clamps' pairs of hits and misses, version 5). Each block's
// cells are written live and ascending by Morton code, and read back with every count, order and
// value checked.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "storage/cell_reader.h"
#include "file/map_codec.h"

namespace wavog {
namespace detail {
namespace {

constexpr std::size_t kNdtBlockBytes = 4 + 4 + 4;      // bx, by, cell count
constexpr std::size_t kNdtCellBytes = 4 + 6 * 8;       // code, moments
constexpr double kMaxNdtWeight = 1e15;                 // end-points of one cell a file may claim
constexpr std::size_t kHitBlockBytes = 4 + 4 + 1 + 4;  // bx, by, kind, cell count
constexpr std::size_t kHitCellBytes = 4 + 4;           // code, count or ratio
constexpr std::size_t kPairCellBytes = 4 + 4 + 4;      // code, hits, misses
constexpr std::size_t kReflectionHeadBytes = 1 + 1 + 3 * 8 + 8;

// The live entries of `runs`, ascending by code.
template <typename Entry>
std::vector<Entry> liveInCodeOrder(const CellRuns<Entry>& runs) {
  std::vector<Entry> cells;
  for (const Entry& e : runs.entries) {
    if (e.live()) cells.push_back(e);
  }
  std::sort(cells.begin(), cells.end(),
            [](const Entry& a, const Entry& b) { return a.code < b.code; });
  return cells;
}

// The clamps' pairs of block `b` with their counts as of now (the misses since each one's last
// hit read from the occupancy), as a file holds them.
CellRuns<HitPair> pairsNow(const WaveletMap::Impl& impl, const Block& b) {
  CellRuns<HitPair> now = b.hits->pairs;
  BlockCellReader occupancy(impl, b);
  for (HitPair& e : now.entries) {
    if (!e.live()) continue;
    const double l = occupancy.average(e.code);
    const PairCounts c = pairNow(e, l, impl.params);
    e.h = static_cast<float>(c.h);
    e.m = static_cast<float>(c.m);
    e.l = static_cast<float>(l);
  }
  return now;
}

// The block (bx, by) of `fresh` that a section says holds n cells of `cell_bytes` each; `what`
// names the payload in the errors.
Block& payloadBlock(WaveletMap::Impl& fresh, std::int32_t bx, std::int32_t by, std::uint32_t n,
                    std::size_t cell_bytes, std::size_t bytes, const char* what) {
  Block* b = fresh.findBlock(bx, by);
  if (b == nullptr) {
    throw std::runtime_error(std::string(what) + " cells in a block the file does not hold");
  }
  const std::uint64_t cells_per_block = std::uint64_t{1} << (2 * fresh.levels);
  if (n == 0 || n > cells_per_block || n > bytes / cell_bytes) {
    throw std::runtime_error(std::string("bad ") + what + " cell count");
  }
  return *b;
}

// Entry j of a block's cells just read: its code must lie in the block and follow entry j - 1's.
template <typename Entry>
void checkCellOrder(const std::vector<Entry>& entries, std::uint32_t j, int levels,
                    const char* what) {
  const std::uint32_t code = entries[j].code;
  if (code >= (std::uint64_t{1} << (2 * levels)) || (j > 0 && code <= entries[j - 1].code)) {
    throw std::runtime_error(std::string(what) + " cells out of order");
  }
}

// The hits of one block's cells: i32 bx | i32 by | u8 kind | u32 n | the live entries.
template <typename Entry>
void writeHitRuns(const CellRuns<Entry>& runs, std::int64_t bx, std::int64_t by, std::uint8_t kind,
                  Writer* w) {
  const std::vector<Entry> cells = liveInCodeOrder(runs);
  if (cells.empty()) return;
  w->put(static_cast<std::int32_t>(bx));
  w->put(static_cast<std::int32_t>(by));
  w->put(kind);
  w->put(static_cast<std::uint32_t>(cells.size()));
  for (const Entry& e : cells) {
    w->put(e.code);
    if constexpr (std::is_same_v<Entry, HitCount>) {
      w->put(e.n);
    } else if constexpr (std::is_same_v<Entry, HitPair>) {
      w->put(e.h);
      w->put(e.m);
    } else {
      w->put(e.q);
    }
  }
}

// Reads n hit cells into `runs` (empty so far).
template <typename Entry>
void readHitRuns(std::uint32_t n, int levels, CellRuns<Entry>* runs, Reader* r) {
  if (!runs->entries.empty()) throw std::runtime_error("duplicate hit block");
  runs->entries.resize(n);
  for (std::uint32_t j = 0; j < n; ++j) {
    Entry& e = runs->entries[j];
    e.code = r->get<std::uint32_t>();
    checkCellOrder(runs->entries, j, levels, "hit");
    if constexpr (std::is_same_v<Entry, HitCount>) {
      e.n = r->get<std::uint32_t>();
    } else if constexpr (std::is_same_v<Entry, HitPair>) {
      e.h = r->get<float>();
      e.m = r->get<float>();
      if (!(std::isfinite(e.h) && std::isfinite(e.m) && e.m >= 0.0f)) {
        throw std::runtime_error("bad hit pair");
      }
    } else {
      e.q = r->get<float>();
      if (!std::isfinite(e.q)) throw std::runtime_error("non-finite hit ratio");
    }
    if (!e.live()) throw std::runtime_error("empty hit cell");
  }
  runs->sorted = n;
}

// The reflection mode "prior" (h + m = 1, h from the occupancy alone) is that of "forget" with
// the empty_bound prior only (Impl::restartReflection; a file's older layers load as "layers"
// under any policy). A file claiming it under another policy read differently by each path: the
// read-out derived a clamp map's hits from its occupancy, the point query read a cell's pair.
bool modeOfPolicy(ReflectionMode m, PolicyType t) {
  return m != ReflectionMode::kPrior || t == PolicyType::kForget;
}

}  // namespace

double payloadSectionsBound(std::uint32_t version, std::uint64_t blocks, int levels) {
  const double cells = std::ldexp(1.0, 2 * levels);
  const auto n = static_cast<double>(blocks);
  double bound = 0.0;
  if (version >= 3) {
    bound += 8.0 +
             n * (static_cast<double>(kNdtBlockBytes) + cells * static_cast<double>(kNdtCellBytes));
  }
  if (version >= 4) {
    // Each block may hold counts, ratios and pairs (8, 8, 12 bytes a cell).
    bound += static_cast<double>(kReflectionHeadBytes) +
             3.0 * n * static_cast<double>(kHitBlockBytes) +
             n * cells * static_cast<double>(2 * kHitCellBytes + kPairCellBytes);
  }
  return bound;
}

// u64 count of blocks holding Gaussians, each: i32 bx | i32 by | u32 n | the live cells.
void writeNdt(const WaveletMap::Impl& impl, Writer* w) {
  std::uint64_t count = 0;
  for (const auto& kv : impl.blocks) count += kv.second.ndt && !kv.second.ndt->empty() ? 1 : 0;
  w->put(count);
  for (const auto& kv : impl.blocks) {
    if (!kv.second.ndt || kv.second.ndt->empty()) continue;
    const std::vector<NdtEntry> cells = liveInCodeOrder(*kv.second.ndt);
    w->put(static_cast<std::int32_t>(blockKeyX(kv.first)));
    w->put(static_cast<std::int32_t>(blockKeyY(kv.first)));
    w->put(static_cast<std::uint32_t>(cells.size()));
    for (const NdtEntry& e : cells) {
      w->put(e.code);
      for (double v : {e.m.w, e.m.sx, e.m.sy, e.m.sxx, e.m.sxy, e.m.syy}) w->put(v);
    }
  }
}

void readNdt(WaveletMap::Impl& fresh, bool keep, std::size_t bytes, Reader* r) {
  const auto count = r->get<std::uint64_t>();
  if (count > bytes / kNdtBlockBytes) throw std::runtime_error("bad NDT block count");
  for (std::uint64_t i = 0; i < count; ++i) {
    const auto bx = r->get<std::int32_t>();
    const auto by = r->get<std::int32_t>();
    const auto n = r->get<std::uint32_t>();
    Block& b = payloadBlock(fresh, bx, by, n, kNdtCellBytes, bytes, "NDT");
    if (b.ndt) throw std::runtime_error("duplicate NDT block");
    auto cells = std::make_unique<NdtCells>();
    cells->entries.resize(n);
    for (std::uint32_t j = 0; j < n; ++j) {
      NdtEntry& e = cells->entries[j];
      e.code = r->get<std::uint32_t>();
      for (double* v : {&e.m.w, &e.m.sx, &e.m.sy, &e.m.sxx, &e.m.sxy, &e.m.syy}) {
        *v = r->get<double>();
        if (!std::isfinite(*v)) throw std::runtime_error("non-finite NDT moment");
      }
      checkCellOrder(cells->entries, j, fresh.levels, "NDT");
      // End-points lie in their cell: |offset| <= res / 2 (with round-off), weights are finite.
      const double h = 0.5 * fresh.params.grid.resolution * (1.0 + 1e-9), w = e.m.w;
      if (!(w > 0.0 && w <= kMaxNdtWeight) || std::fabs(e.m.sx) > w * h ||
          std::fabs(e.m.sy) > w * h || !(e.m.sxx >= 0.0 && e.m.sxx <= w * h * h) ||
          !(e.m.syy >= 0.0 && e.m.syy <= w * h * h) || std::fabs(e.m.sxy) > w * h * h) {
        throw std::runtime_error("NDT cell with moments no end-points in the cell can have");
      }
    }
    cells->sorted = n;
    if (keep) b.ndt = std::move(cells);
  }
}

// u8 mode | u8 policy | f64 odd_occ odd_emp prior | u64 count of hit blocks, each writeHitRuns.
void writeReflection(const WaveletMap::Impl& impl, Writer* w) {
  w->put(static_cast<std::uint8_t>(impl.reflection_mode));
  const ReflectionBasis& b = impl.reflection_basis;
  w->put(static_cast<std::uint8_t>(b.type));
  w->put(b.odd_occ);
  w->put(b.odd_emp);
  w->put(b.init);
  std::uint64_t count = 0;
  for (const auto& kv : impl.blocks) {
    if (!kv.second.hits) continue;
    count += kv.second.hits->counts.empty() ? 0 : 1;
    count += kv.second.hits->ratios.empty() ? 0 : 1;
    count += kv.second.hits->pairs.empty() ? 0 : 1;
  }
  w->put(count);
  for (const auto& kv : impl.blocks) {
    if (!kv.second.hits) continue;
    const std::int64_t bx = blockKeyX(kv.first), by = blockKeyY(kv.first);
    writeHitRuns(kv.second.hits->counts, bx, by, 0, w);
    writeHitRuns(kv.second.hits->ratios, bx, by, 1, w);
    if (!kv.second.hits->pairs.empty()) writeHitRuns(pairsNow(impl, kv.second), bx, by, 2, w);
  }
}

FileReflection readReflection(WaveletMap::Impl& fresh, bool keep, std::uint32_t version,
                              std::size_t bytes, Reader* r) {
  FileReflection f;
  const auto mode = r->get<std::uint8_t>();
  const auto type = r->get<std::uint8_t>();
  if (mode > static_cast<std::uint8_t>(ReflectionMode::kLayers) ||
      type > static_cast<std::uint8_t>(PolicyType::kClampUpper)) {
    throw std::runtime_error("bad reflection mode");
  }
  f.mode = static_cast<ReflectionMode>(mode);
  f.basis.type = static_cast<PolicyType>(type);
  if (!modeOfPolicy(f.mode, f.basis.type)) {
    throw std::runtime_error("reflection mode " + std::to_string(mode) + " (prior) under policy " +
                             toString(f.basis.type) + ": only forget keeps it");
  }
  f.basis.odd_occ = r->get<double>();
  f.basis.odd_emp = r->get<double>();
  f.basis.init = r->get<double>();
  const auto count = r->get<std::uint64_t>();
  if (count > bytes / kHitBlockBytes) throw std::runtime_error("bad hit block count");
  for (std::uint64_t i = 0; i < count; ++i) {
    const auto bx = r->get<std::int32_t>();
    const auto by = r->get<std::int32_t>();
    const auto kind = r->get<std::uint8_t>();
    const auto n = r->get<std::uint32_t>();
    // The kind of entries the policy keeps: ratios under "forget", pairs under the clamps (since
    // version 5), counts otherwise.
    const std::uint8_t expected = f.basis.type == PolicyType::kForget          ? 1
                                  : boundsCounts(f.basis.type) && version >= 5 ? 2
                                                                               : 0;
    if (kind != expected) throw std::runtime_error("hit kind does not match the policy");
    Block& b =
        payloadBlock(fresh, bx, by, n, kind == 2 ? kPairCellBytes : kHitCellBytes, bytes, "hit");
    if (!b.hits) b.hits = std::make_unique<HitCells>();
    if (kind == 0) {
      readHitRuns(n, fresh.levels, &b.hits->counts, r);
    } else if (kind == 1) {
      readHitRuns(n, fresh.levels, &b.hits->ratios, r);
    } else {
      readHitRuns(n, fresh.levels, &b.hits->pairs, r);
      // The counts are as of the file's occupancy (read before the hits).
      BlockCellReader occupancy(fresh, b);
      for (HitPair& e : b.hits->pairs.entries) e.l = static_cast<float>(occupancy.average(e.code));
    }
  }
  // Before version 5 the clamps counted without bound: such a reflection map restarts.
  if (version < 5 && boundsCounts(f.basis.type)) f.mode = ReflectionMode::kOff;
  if (!keep) {
    for (auto& kv : fresh.blocks) kv.second.hits.reset();
  }
  return f;
}

}  // namespace detail
}  // namespace wavog
