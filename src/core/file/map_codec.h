// The byte codec of native map files (map_io.cpp, the layout there): a writer and a bounds-checked
// reader of little-endian values, the payload sections map_payload_io.cpp reads and writes (the
// blocks' normal-distribution cells and the reflection map's hits) and the tiles of
// map_tile_io.cpp. Not installed; included only by src/core/file/*.cpp.
#ifndef WAVOG_MAPPING_SRC_CORE_FILE_MAP_CODEC_H_
#define WAVOG_MAPPING_SRC_CORE_FILE_MAP_CODEC_H_

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "storage/map_impl.h"

namespace wavog {
namespace detail {

class Writer {
 public:
  template <typename T>
  void put(T v) {
    bytes(&v, sizeof(T));
  }
  void bytes(const void* p, std::size_t n) {
    const std::size_t at = buf_.size();
    buf_.resize(at + n);
    std::memcpy(buf_.data() + at, p, n);
  }
  std::vector<unsigned char>& buffer() { return buf_; }

 private:
  std::vector<unsigned char> buf_;
};

class Reader {
 public:
  Reader(const unsigned char* data, std::size_t size) : p_(data), end_(data + size) {}
  template <typename T>
  T get() {
    if (static_cast<std::size_t>(end_ - p_) < sizeof(T)) throw std::out_of_range("truncated");
    T v;
    std::memcpy(&v, p_, sizeof(T));
    p_ += sizeof(T);
    return v;
  }
  bool done() const { return p_ == end_; }

 private:
  const unsigned char* p_;
  const unsigned char* end_;
};

/// The largest size of the payload sections of a file of `version` with `blocks` blocks of
/// `levels` levels (every cell of every block with a Gaussian and a hit), for the size check
/// before a file is read.
double payloadSectionsBound(std::uint32_t version, std::uint64_t blocks, int levels);

/// The normal-distribution cells (version 3): writes those of `impl`; reads them into `fresh`'s
/// blocks (read before), or drops them when not `keep` (a map without ndt). Throws
/// std::runtime_error on inconsistent data.
void writeNdt(const WaveletMap::Impl& impl, Writer* w);
void readNdt(WaveletMap::Impl& fresh, bool keep, std::size_t bytes, Reader* r);

/// What a file says of its reflection map: its mode and the basis it was built under.
struct FileReflection {
  ReflectionMode mode = ReflectionMode::kOff;
  ReflectionBasis basis;
};

/// The reflection section (version 4): writes `impl`'s mode, basis and hits; reads them, the hits
/// into `fresh`'s blocks (read before), dropped when not `keep`. Throws std::runtime_error on
/// inconsistent data.
void writeReflection(const WaveletMap::Impl& impl, Writer* w);
FileReflection readReflection(WaveletMap::Impl& fresh, bool keep, std::uint32_t version,
                              std::size_t bytes, Reader* r);

/// The refusal of a log-odds the update cannot carry (limits.h, kMaxStoredLogOdds).
std::string beyondBound(const char* what, double value);

/// A tile node's tile (version 7; map_tile_io.cpp): written after its node; read into node n of
/// a fresh map (its flags read and checked). Throw std::runtime_error on inconsistent data.
void writeTile(const WaveletMap::Impl& impl, const Node& n, Writer* w);
void readTile(WaveletMap::Impl& impl, Node& n, Reader* r);
/// Node n of the tile level, read as a Haar node with its subtree, made a tile node.
void makeTile(WaveletMap::Impl& impl, Node& n);

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_FILE_MAP_CODEC_H_
