// Writing a file so that a crash, a kill -9 or a planted symlink can do no harm: the map files and
// every file the tools and the node write beside them (images, map_server YAML) go through it.
#ifndef WAVOG_MAPPING_CORE_ATOMIC_FILE_H_
#define WAVOG_MAPPING_CORE_ATOMIC_FILE_H_

#include <cstddef>
#include <string>

namespace wavog {

/// Writes `size` bytes at `data` to `path` through a new temporary file in the same directory,
/// created exclusively (O_CREAT | O_EXCL | O_NOFOLLOW: never an existing file, never through a
/// symlink), synced to disk, then renamed over `path` (a symlink planted at `path` is replaced,
/// its target untouched), and the directory synced. The file on disk is at every moment either the
/// old one or the complete new one; the temporary is removed on failure. Throws MapIoError (a
/// std::runtime_error) naming the file and the reason.
void writeFileAtomically(const std::string& path, const void* data, std::size_t size);

}  // namespace wavog

#endif  // WAVOG_MAPPING_CORE_ATOMIC_FILE_H_
