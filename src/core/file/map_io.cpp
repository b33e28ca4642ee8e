// Native map files. Layout (little-endian, version 7):
//   "WAVOGMAP" | u32 version | f64 resolution | i32 block_levels | f64 prior | f64 a (the factor
//   one pending unit stands for: 1 - gamma, or 2^-unit with forget_half_life) | u64 block count
//   per block: i32 bx | i32 by | f64 average | u8 flags (1 known_all, 2 known_any, 4 has_root)
//              [root subtree, pre-order: f64 dx dy dxy (stored) | u16 pending count k |
//               u8 child_mask | u8 known_all | u8 known_any | children in q order; a tile node
//               (storage/tile.h; child_mask 0x10, at the tile level; a node there may also be
//               a Haar node with children, made a tile on loading) is followed by its tile:
//               u64 known | f64 base | f64 cells, row by row (8 x 8, or 4 x 4 in blocks of 2
//               levels)]
//   u8 reflection layers, a mask (1: hits, 2: misses; before version 4 their count, hits first),
//   each: f64 a | u64 block count | blocks as above
//   u64 count of blocks with normal-distribution cells (MapParams::ndt), each: i32 bx | i32 by |
//   u32 n | n cells ascending by Morton code within the block: u32 code | f64 w sx sy sxx sxy syy
//   (moments about the cell's centre, ndt_store.h)
//   u8 reflection mode (0 none, 1 derived, 2 prior, 3 counts, 4 layers: map_impl.h) | u8 policy |
//   f64 odd_occ odd_emp prior (the basis it was built under) | u64 count of blocks with hits,
//   each: i32 bx | i32 by | u8 kind (0 counts, 1 ratios, 2 pairs) | u32 n | n cells ascending by
//   code: u32 code | u32 count, f32 ratio, or f32 hits f32 misses (reflection_store.h)
//   u32 CRC-32 (IEEE) of every byte before it.
// Version 6 is the same without tiles (the levels below them are nodes; they are made tiles on
// loading). Version 5 is the same with f32 details (before issue 37: the nodes held floats).
// Version 4 is the same without pairs (the clamps counted without bound; such a reflection map
// restarts on loading). Version 3 (before the hits) is the same without the reflection section (its
// layers hold the hits and misses: kLayers), version 2 (before ndt) also without the NDT section,
// version 1 (before forget_half_life and reflection) also with a u8 pending count and no layers;
// all load. Stored details and lazy counts are written as they are, so a round trip is bit-exact; a
// map loaded under another factor applies the file's pending tags while loading. Files are written
// and read through map_file.h (exclusive temporary + rename, regular files only); the payload
// sections (Gaussians, hits) are map_payload_io.cpp's, the tiles map_tile_io.cpp's.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "file/map_codec.h"
#include "file/map_file.h"
#include "storage/map_impl.h"
#include "wavog_mapping/core/haar.h"
#include "wavog_mapping/core/limits.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog {

namespace detail {
std::string beyondBound(const char* what, double value) {
  std::ostringstream s;
  s << what << " of " << value << " log-odds, beyond the +-" << kMaxStoredLogOdds
    << " an update keeps finite";
  return s.str();
}
}  // namespace detail

namespace {

using detail::beyondBound;

using detail::Block;
using detail::Node;
using detail::Reader;
using detail::Writer;

constexpr char kMagic[8] = {'W', 'A', 'V', 'O', 'G', 'M', 'A', 'P'};
constexpr std::uint32_t kVersion = 7;
constexpr std::uint32_t kOldestVersion = 1;  // u8 pending counts
// Fixed header: magic, version, resolution, block_levels, prior, forgetting factor, block count.
constexpr std::size_t kHeaderBytes = sizeof(kMagic) + 4 + 8 + 4 + 8 + 8 + 8;
constexpr std::size_t kCrcBytes = 4;
constexpr std::size_t kMinBlockBytes = 4 + 4 + 8 + 1;  // bx, by, average, flags
// Three details (f64 from version 6, f32 before), k, mask, known bits.
std::size_t nodeBytes(std::uint32_t version) {
  return 3 * (version >= 6 ? 8 : 4) + (version == 1 ? 1 : 2) + 3;
}

std::uint32_t crc32(const unsigned char* data, std::size_t size) {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) c = table[(c ^ data[i]) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

void writeNode(const WaveletMap::Impl& impl, const Node& n, int l, Writer* w) {
  for (double d : n.d) w->put(d);
  w->put(n.k);
  w->put(n.child_mask);
  w->put(static_cast<std::uint8_t>(n.known_all));
  w->put(static_cast<std::uint8_t>(n.known_any));
  if (WaveletMap::Impl::hasTile(n)) {
    detail::writeTile(impl, n, w);
    return;
  }
  if (l <= 1) return;
  for (int q = 0; q < 4; ++q) {
    if (impl.hasChild(n, q)) writeNode(impl, impl.child(n, q), l - 1, w);
  }
}

// How a file's pending counts are read: their width and the factor one unit stands for.
struct PendingFormat {
  std::uint32_t version;
  double file_a;
  bool same_unit;  // file_a is the map's unit factor: counts are kept as they are
};

// The knowledge a map can hold (map_slot.h, refineSlot): a node's is the one its slot records
// (known_all: all four children known entirely; known_any: some), and a slot without a node of
// its own (a finest cell, a uniform child, a block without a root) is observed entirely or not at
// all. A file claiming otherwise would read differently by each path (value() by known_all, the
// read-outs by known_any, the max read-out finding no observed cell under an observed slot).
void checkSlotKnowledge(bool slot_all, bool slot_any, unsigned known_all, unsigned known_any) {
  if (slot_all != (known_all == 0xFu) || slot_any != (known_any != 0)) {
    throw std::runtime_error("a node's knowledge disagrees with its parent's");
  }
}
void checkUniformKnowledge(bool all, bool any) {
  if (all != any) throw std::runtime_error("a uniform slot partly observed");
}

// Reads a subtree into `impl` (a fresh map); `slot_all` / `slot_any`: the knowledge its slot
// records. Throws std::runtime_error on inconsistent data.
// A node's pending count is kept when it means the same for the map (and fits its counts);
// otherwise it is applied now with the file's factor, together with `pending`, the ancestors'
// counts applied the same way.
void readNode(WaveletMap::Impl& impl, Node& n, int l, const PendingFormat& f, std::int64_t pending,
              bool slot_all, bool slot_any, Reader* r) {
  for (double& d : n.d) {
    d = f.version >= 6 ? r->get<double>() : static_cast<double>(r->get<float>());
    if (!std::isfinite(d)) throw std::runtime_error("non-finite detail");
    if (std::fabs(d) > kMaxStoredLogOdds) throw std::runtime_error(beyondBound("a detail", d));
  }
  const unsigned k = f.version == 1 ? r->get<std::uint8_t>() : r->get<std::uint16_t>();
  double applied = 1.0;  // the factor applied now (a tile's too)
  if (f.same_unit && pending == 0 && k <= impl.k_cap) {
    n.k = static_cast<std::uint16_t>(k);
  } else {
    pending += k;
    applied = std::pow(f.file_a, static_cast<double>(pending));
    for (double& d : n.d) d *= applied;
    n.k = 0;
  }
  const auto mask = r->get<std::uint8_t>();
  const auto known_all = r->get<std::uint8_t>();
  const auto known_any = r->get<std::uint8_t>();
  const bool tile = mask == detail::kTileBit && f.version >= 7;
  if ((mask > 0xF && !tile) || known_all > 0xF || known_any > 0xF ||
      (known_all & ~known_any) != 0) {
    throw std::runtime_error("bad node flags");
  }
  n.known_all = known_all & 0xFu;
  n.known_any = known_any & 0xFu;
  if (l == 1 && mask != 0) throw std::runtime_error("children below level 1");
  checkSlotKnowledge(slot_all, slot_any, known_all, known_any);
  if (tile) {
    if (l != impl.tile_level) throw std::runtime_error("a tile off the tile level");
    detail::readTile(impl, n, r);
    if (applied != 1.0) impl.withTile(n, [&](auto& t) { detail::scaleTile(&t, applied); });
    return;
  }
  for (int q = 0; q < 4; ++q) {
    const bool all = (known_all >> q) & 1u, any = (known_any >> q) & 1u;
    if (!((mask >> q) & 1u)) {
      checkUniformKnowledge(all, any);
      continue;
    }
    Node& c = impl.installChild(n, q, Node{});
    readNode(impl, c, l - 1, f, pending, all, any, r);
  }
  if (l == impl.tile_level) detail::makeTile(impl, n);
}

// Opens `path` (a regular file only) and reads it whole, once its header says it is a map of this
// format whose size fits its block count at `levels` (the map's block_levels, which the file must
// match): a file larger than its blocks could fill is refused before it is read.
std::vector<unsigned char> readMapFile(const std::string& path, int levels) {
  const detail::RegularFile file(path);
  const auto fail = [&](const std::string& why) {
    return MapIoError("map file '" + path + "' rejected: " + why);
  };
  const std::uint64_t size = file.size();
  const auto head =
      file.read(0, static_cast<std::size_t>(std::min<std::uint64_t>(size, kHeaderBytes)));
  if (head.size() < sizeof(kMagic) + 4 || std::memcmp(head.data(), kMagic, sizeof(kMagic)) != 0) {
    throw fail("not a wavog map (bad magic)");
  }
  std::uint32_t version;
  std::memcpy(&version, head.data() + sizeof(kMagic), sizeof(version));
  if (version < kOldestVersion || version > kVersion) {
    throw fail("format version " + std::to_string(version) + ", this build reads versions " +
               std::to_string(kOldestVersion) + " to " + std::to_string(kVersion));
  }
  if (size < kHeaderBytes + kCrcBytes) throw fail("truncated (" + std::to_string(size) + " bytes)");
  std::uint64_t count;
  std::memcpy(&count, head.data() + kHeaderBytes - sizeof(count), sizeof(count));
  // A full block: its header and one node per level-l node of the quadtree, (4^L - 1) / 3.
  const double nodes_per_block = (std::ldexp(1.0, 2 * levels) - 1.0) / 3.0;
  // Version 2 may add two reflection layers over the same blocks (each with its unit factor and
  // count, and the layer count byte).
  const double maps = version >= 2 ? 3.0 : 1.0;
  const double largest = static_cast<double>(kHeaderBytes + kCrcBytes) + (maps - 1.0) * 17.0 + 1.0 +
                         maps * static_cast<double>(count) *
                             (static_cast<double>(kMinBlockBytes) +
                              nodes_per_block * static_cast<double>(nodeBytes(version)));
  // Versions 3 and 4 add the Gaussians and the hits: at most every cell of every block.
  const double payloads = detail::payloadSectionsBound(version, count, levels);
  if (static_cast<double>(size) > largest + payloads) {
    throw fail(std::to_string(size) + " bytes, more than its " + std::to_string(count) +
               " blocks can fill (at most " +
               std::to_string(static_cast<std::uint64_t>(largest + payloads)) +
               " bytes at block_levels " + std::to_string(levels) + ")");
  }
  if (size > std::numeric_limits<std::size_t>::max()) throw fail("too large to read");
  return file.read(0, static_cast<std::size_t>(size));
}

}  // namespace

namespace {

// The blocks section of one map (the main map or a reflection layer): u64 count, then the blocks.
void writeBlocks(const WaveletMap::Impl& impl, Writer* w) {
  w->put(static_cast<std::uint64_t>(impl.blocks.size()));
  for (const auto& kv : impl.blocks) {
    const Block& b = kv.second;
    w->put(static_cast<std::int32_t>(detail::blockKeyX(kv.first)));
    w->put(static_cast<std::int32_t>(detail::blockKeyY(kv.first)));
    w->put(b.s);
    w->put(static_cast<std::uint8_t>((b.known_all ? 1 : 0) | (b.known_any ? 2 : 0) |
                                     (b.has_root ? 4 : 0)));
    if (b.has_root) writeNode(impl, b.root, impl.levels, w);
  }
}

// Reads a blocks section into `fresh` (an empty map); `bytes`: the file's size, bounding the count.
void readBlocks(WaveletMap::Impl& fresh, const PendingFormat& format, std::size_t bytes,
                Reader* r) {
  const auto count = r->get<std::uint64_t>();
  if (count > bytes / kMinBlockBytes) {
    throw std::runtime_error(std::to_string(count) + " blocks cannot fit in " +
                             std::to_string(bytes) + " bytes");
  }
  for (std::uint64_t i = 0; i < count; ++i) {
    const auto bx = r->get<std::int32_t>();
    const auto by = r->get<std::int32_t>();
    const auto s = r->get<double>();
    const auto flags = r->get<std::uint8_t>();
    if (!std::isfinite(s) || flags > 7) throw std::runtime_error("bad block header");
    if (std::fabs(s) > kMaxStoredLogOdds) {
      throw std::runtime_error(beyondBound("a block average", s));
    }
    if (!inExtent(detail::scaleUp(bx, fresh.levels), detail::scaleUp(by, fresh.levels))) {
      throw std::runtime_error("block (" + std::to_string(bx) + ", " + std::to_string(by) +
                               ") outside the representable extent of +-2^30 cells");
    }
    auto ins = fresh.blocks.try_emplace(detail::blockKey(bx, by));
    if (!ins.second) throw std::runtime_error("duplicate block");
    Block& b = ins.first->second;
    b.s = s;
    b.known_all = flags & 1;
    b.known_any = (flags & 2) != 0;
    b.has_root = (flags & 4) != 0;
    if (b.has_root) {
      ++fresh.counts.nodes;
      readNode(fresh, b.root, fresh.levels, format, 0, b.known_all, b.known_any, r);
    } else {
      checkUniformKnowledge(b.known_all, b.known_any);
    }
  }
}

double readUnitFactor(Reader* r) {
  const auto a = r->get<double>();
  if (!(a >= 0.0 && a <= 1.0)) throw std::runtime_error("bad forgetting factor");
  return a;
}

}  // namespace

void WaveletMap::save(const std::string& path) const {
  const Impl& impl = *impl_;
  Writer w;
  w.bytes(kMagic, sizeof(kMagic));
  w.put(kVersion);
  w.put(impl.params.grid.resolution);
  w.put(static_cast<std::int32_t>(impl.levels));
  w.put(impl.init);
  w.put(impl.unitFactor());
  writeBlocks(impl, &w);
  // Reflection layers: u8 mask (1: hits, 2: misses), each its unit factor and its blocks.
  const WaveletMap* layers[2] = {impl.hits_layer.get(), impl.misses_layer.get()};
  w.put(static_cast<std::uint8_t>((layers[0] != nullptr ? 1 : 0) | (layers[1] != nullptr ? 2 : 0)));
  for (const WaveletMap* layer : layers) {
    if (layer == nullptr) continue;
    const Impl& l = *layer->impl_;
    w.put(l.unitFactor());
    writeBlocks(l, &w);
  }
  detail::writeNdt(impl, &w);
  detail::writeReflection(impl, &w);
  auto& buf = w.buffer();
  const std::uint32_t crc = crc32(buf.data(), buf.size());
  w.put(crc);

  detail::writeFileAtomically(path, buf);
}

void WaveletMap::load(const std::string& path) { load(path, nullptr); }

MapFileContents WaveletMap::inspectFile(const std::string& path) {
  // The grid from the header (load() checks the rest), then a load keeping both payloads.
  MapParams p;
  {
    const detail::RegularFile file(path);
    const auto head = file.read(0, static_cast<std::size_t>(
                                       std::min<std::uint64_t>(file.size(), kHeaderBytes)));
    if (head.size() < kHeaderBytes || std::memcmp(head.data(), kMagic, sizeof(kMagic)) != 0) {
      throw MapIoError("map file '" + path + "' rejected: not a wavog map (bad magic or header)");
    }
    std::int32_t levels;
    std::memcpy(&p.grid.resolution, head.data() + sizeof(kMagic) + 4, sizeof(double));
    std::memcpy(&levels, head.data() + sizeof(kMagic) + 12, sizeof(levels));
    p.grid.block_levels = levels;
  }
  p.reflection = p.ndt = true;
  if (!p.validate().empty()) {
    std::ostringstream s;
    s << "map file '" << path << "' rejected: its resolution " << p.grid.resolution
      << " m / block_levels " << p.grid.block_levels << " are outside the valid ranges";
    throw MapIoError(s.str());
  }
  WaveletMap probe(p);
  MapFileContents contents;
  probe.load(path, &contents);
  return contents;
}

void WaveletMap::load(const std::string& path, MapFileContents* contents) {
  const std::vector<unsigned char> data = readMapFile(path, impl_->levels);
  const auto fail = [&](const std::string& why) {
    return MapIoError("map file '" + path + "' rejected: " + why);
  };
  const std::size_t body = data.size() - kCrcBytes;
  std::uint32_t stored_crc;
  std::memcpy(&stored_crc, data.data() + body, kCrcBytes);
  if (crc32(data.data(), body) != stored_crc) {
    throw fail("checksum mismatch (truncated or corrupted)");
  }

  Impl fresh(impl_->params);
  try {
    std::uint32_t version;
    std::memcpy(&version, data.data() + sizeof(kMagic), sizeof(version));
    Reader r(data.data() + sizeof(kMagic) + 4, body - sizeof(kMagic) - 4);
    const auto res = r.get<double>();
    const auto levels = r.get<std::int32_t>();
    (void)r.get<double>();  // prior at save time: informative only
    const double file_a = readUnitFactor(&r);
    if (res != impl_->params.grid.resolution || levels != impl_->levels) {
      std::ostringstream s;
      s << "its resolution " << res << " m / block_levels " << levels << " differ from this map's "
        << impl_->params.grid.resolution << " m / " << impl_->levels;
      throw fail(s.str());
    }
    readBlocks(fresh, PendingFormat{version, file_a, file_a == fresh.unitFactor()}, data.size(),
               &r);
    // Reflection layers (version >= 2), read into maps of the file's layers.
    std::unique_ptr<WaveletMap> file_layers[2];
    if (version >= 2) {
      // Version 4: a mask of the layers; before, their count (hits first).
      const auto n = r.get<std::uint8_t>();
      if (n > 3 || (version < 4 && n > 2)) throw std::runtime_error("bad reflection layers");
      const unsigned mask = version >= 4 ? n : (1u << n) - 1u;
      for (int i = 0; i < 2; ++i) {
        if (!((mask >> i) & 1u)) continue;
        file_layers[i].reset(new WaveletMap(
            Impl::layerParams(impl_->params, i == 0, ReflectionMode::kLayers), LayerTag{}));
        Impl& into = *file_layers[i]->impl_;
        const double layer_a = readUnitFactor(&r);
        readBlocks(into, PendingFormat{version, layer_a, layer_a == into.unitFactor()}, data.size(),
                   &r);
      }
    }
    if (version >= 3) detail::readNdt(fresh, impl_->params.ndt, data.size(), &r);
    detail::FileReflection file;
    if (version >= 4) {
      file = detail::readReflection(fresh, impl_->params.reflection, version, data.size(), &r);
    } else if (file_layers[0]) {
      file.mode = ReflectionMode::kLayers;  // the hits and misses of older files
      file.basis = fresh.currentBasis();    // not recorded; the layers count whatever it was
    }
    const bool held_reflection =
        file.mode != ReflectionMode::kOff || file_layers[0] != nullptr || file_layers[1] != nullptr;
    if (impl_->params.reflection) {
      fresh.adoptReflection(file.mode, file.basis, std::move(file_layers[0]),
                            std::move(file_layers[1]));
    }
    if (!r.done()) throw std::runtime_error("trailing bytes");
    if (contents != nullptr) {
      contents->reflection = held_reflection;
      contents->ndt = false;  // the Gaussians the file held (kept: inspectFile's map has ndt)
      for (const auto& kv : fresh.blocks) contents->ndt |= kv.second.ndt && !kv.second.ndt->empty();
    }
  } catch (const MapIoError&) {
    throw;
  } catch (const std::exception& e) {
    throw fail(std::string("malformed content: ") + e.what());
  }
  fresh.workers = std::move(impl_->workers);  // the threads live as long as the map
  *impl_ = std::move(fresh);
}

}  // namespace wavog
