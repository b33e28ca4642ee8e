// Figures of WaveletMap: stats() counts blocks, nodes, bytes used and reserved (normal-distribution
// cells included), the last scan's visits and (on request) the observed cells.
#include "storage/map_impl.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog {

using detail::Block;
using detail::Node;

namespace {
std::uint64_t countObserved(const WaveletMap::Impl& impl, const Node& n, int l) {
  if (impl.hasTile(n)) {
    const std::uint64_t known = impl.withTile(n, [](const auto& t) { return t.known; });
    return static_cast<std::uint64_t>(
        __builtin_popcountll(known & detail::tileCells(impl.tile_level)));
  }
  std::uint64_t count = 0;
  for (int q = 0; q < 4; ++q) {
    if (l > 1 && impl.hasChild(n, q)) {
      count += countObserved(impl, impl.child(n, q), l - 1);
    } else if ((n.known_all >> q) & 1u) {
      count += std::uint64_t{1} << (2 * (l - 1));
    }
  }
  return count;
}
}  // namespace

MapStats WaveletMap::stats(bool count_observed) const {
  const Impl& impl = *impl_;
  MapStats st;
  st.blocks = impl.blocks.size();
  st.nodes = impl.counts.nodes;
  st.tiles = impl.counts.tiles;
  // Hash: one heap node per block (key, Block, next pointer, cached hash) plus the bucket array.
  const std::size_t per_block = sizeof(std::uint64_t) + sizeof(Block) + 2 * sizeof(void*);
  // The blocks' spare node groups are chained in the pool's chunks (bytes_reserved).
  const std::size_t rest = impl.blocks.size() * per_block +
                           impl.blocks.bucket_count() * sizeof(void*) + sizeof(Impl);
  std::size_t hit_bytes = 0;
  for (const auto& kv : impl.blocks) {
    const detail::HitCells* hits = kv.second.hits.get();
    if (hits == nullptr) continue;
    hit_bytes += sizeof(detail::HitCells) +
                 hits->counts.entries.capacity() * sizeof(detail::HitCount) +
                 hits->ratios.entries.capacity() * sizeof(detail::HitRatio) +
                 hits->pairs.entries.capacity() * sizeof(detail::HitPair) + hits->bits.bytes();
  }
  st.reflection_bytes = hit_bytes;
  for (const auto& kv : impl.blocks) {
    const detail::NdtCells* ndt = kv.second.ndt.get();
    if (ndt == nullptr) continue;
    st.ndt_cells += ndt->entries.size() - ndt->dead;
    st.ndt_bytes += sizeof(detail::NdtCells) + ndt->entries.capacity() * sizeof(detail::NdtEntry);
  }
  st.bytes = impl.pool.bytes(impl.counts.groups) + impl.tiles.bytes(impl.counts.tiles) + rest +
             st.ndt_bytes + hit_bytes;
  st.bytes_reserved =
      impl.pool.bytesReserved() + impl.tiles.bytesReserved() + rest + st.ndt_bytes + hit_bytes;
  st.nodes_visited_last = impl.nodes_visited_last;
  for (const WaveletMap* layer : {impl.hits_layer.get(), impl.misses_layer.get()}) {
    if (layer == nullptr) continue;
    const MapStats ls = layer->stats();
    st.reflection_bytes += ls.bytes;
    st.bytes += ls.bytes;
    st.bytes_reserved += ls.bytes_reserved;
  }
  if (count_observed) {
    for (const auto& kv : impl.blocks) {
      const Block& b = kv.second;
      if (b.has_root) {
        st.observed_cells += countObserved(impl, b.root, impl.levels);
      } else if (b.known_all) {
        st.observed_cells += std::uint64_t{1} << (2 * impl.levels);
      }
    }
  }
  return st;
}

}  // namespace wavog
