// File access of the map files (POSIX): a save that a crash or kill -9 cannot leave half-written,
// and a load that reads regular files only. The format itself lives in map_io.cpp.
// Not installed; included only by src/core/*.cpp. Every failure throws MapIoError naming the file.
#ifndef WAVOG_MAPPING_SRC_CORE_FILE_MAP_FILE_H_
#define WAVOG_MAPPING_SRC_CORE_FILE_MAP_FILE_H_

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace wavog {
namespace detail {

/// wavog::writeFileAtomically (wavog_mapping/core/atomic_file.h) for a map file's bytes.
void writeFileAtomically(const std::string& path, const std::vector<unsigned char>& data);

/// An open regular file, read by position. Opening never blocks (a FIFO without a writer, a
/// device) and refuses anything but a regular file, naming what it is.
class RegularFile {
 public:
  explicit RegularFile(const std::string& path);
  ~RegularFile();
  RegularFile(const RegularFile&) = delete;
  RegularFile& operator=(const RegularFile&) = delete;

  /// Size (bytes) at opening.
  std::uint64_t size() const { return size_; }
  /// Reads bytes [offset, offset + n); throws if the file no longer holds them.
  std::vector<unsigned char> read(std::uint64_t offset, std::size_t n) const;

 private:
  std::string path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_FILE_MAP_FILE_H_
