// POSIX file access of the map files: exclusive temporary + fsync + rename on save, regular files
// only (opened without blocking) on load.
#include "file/map_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <random>

#include "wavog_mapping/core/atomic_file.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog {
namespace detail {
namespace {

std::string errnoText() { return std::strerror(errno); }

/// What a non-regular file is, for the refusal message.
const char* fileKind(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::string directoryOf(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

/// Creates a new file `<path>.tmp.<random>` exclusively; returns its descriptor and name.
int createTemporary(const std::string& path, std::string* tmp) {
  // The name only has to be unlikely to exist: O_EXCL makes the creation itself safe, and a
  // collision (or a planted file or symlink) just draws another name.
  constexpr int kAttempts = 64;
  std::random_device seed;
  std::mt19937_64 rng((static_cast<std::uint64_t>(seed()) << 32) ^ seed() ^
                      static_cast<std::uint64_t>(::getpid()));
  for (int i = 0; i < kAttempts; ++i) {
    static const char kHex[] = "0123456789abcdef";
    std::string name = path + ".tmp.";
    std::uint64_t bits = rng();
    for (int k = 0; k < 12; ++k, bits >>= 4) name += kHex[bits & 0xF];
    const int fd = ::open(name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd >= 0) {
      *tmp = name;
      return fd;
    }
    if (errno != EEXIST) {
      throw MapIoError("cannot create a temporary file '" + name + "': " + errnoText());
    }
  }
  throw MapIoError("cannot create a temporary file beside '" + path +
                   "': " + std::to_string(kAttempts) + " names taken");
}

void writeAll(int fd, const unsigned char* data, std::size_t size, const std::string& name) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, data + done, size - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw MapIoError("cannot write file '" + name + "': " + errnoText());
    }
    done += static_cast<std::size_t>(n);
  }
}

}  // namespace

void writeFileAtomically(const std::string& path, const std::vector<unsigned char>& data) {
  wavog::writeFileAtomically(path, data.data(), data.size());
}

}  // namespace detail

void writeFileAtomically(const std::string& path, const void* data, std::size_t size) {
  std::string tmp;
  const int fd = detail::createTemporary(path, &tmp);
  try {
    detail::writeAll(fd, static_cast<const unsigned char*>(data), size, tmp);
    if (::fsync(fd) != 0) {
      throw MapIoError("cannot sync file '" + tmp + "': " + detail::errnoText());
    }
  } catch (...) {
    ::close(fd);
    ::unlink(tmp.c_str());
    throw;
  }
  if (::close(fd) != 0) {
    const std::string why = detail::errnoText();
    ::unlink(tmp.c_str());
    throw MapIoError("cannot write file '" + tmp + "': " + why);
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string why = detail::errnoText();
    ::unlink(tmp.c_str());
    throw MapIoError("cannot rename '" + tmp + "' to '" + path + "': " + why);
  }
  // Makes the rename itself durable. Some file systems cannot sync a directory; the map is
  // complete on disk either way, so that is not an error.
  const int dir = ::open(detail::directoryOf(path).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    (void)::fsync(dir);
    ::close(dir);
  }
}

namespace detail {

RegularFile::RegularFile(const std::string& path) : path_(path) {
  // O_NONBLOCK: opening a FIFO without a writer (or a device waiting for a carrier) returns at
  // once; the fstat below refuses it. It is cleared again for the regular file.
  fd_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd_ < 0) throw MapIoError("cannot open map file '" + path + "': " + errnoText());
  struct stat st {};
  if (::fstat(fd_, &st) != 0) {
    const std::string why = errnoText();
    ::close(fd_);
    throw MapIoError("cannot open map file '" + path + "': " + why);
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd_);
    throw MapIoError("map file '" + path + "' rejected: " + fileKind(st.st_mode) +
                     ", not a regular file");
  }
  const int flags = ::fcntl(fd_, F_GETFL);
  if (flags >= 0) (void)::fcntl(fd_, F_SETFL, flags & ~O_NONBLOCK);
  size_ = static_cast<std::uint64_t>(st.st_size);
}

RegularFile::~RegularFile() {
  if (fd_ >= 0) ::close(fd_);
}

std::vector<unsigned char> RegularFile::read(std::uint64_t offset, std::size_t n) const {
  std::vector<unsigned char> out(n);
  std::size_t done = 0;
  while (done < n) {
    const ssize_t got =
        ::pread(fd_, out.data() + done, n - done, static_cast<off_t>(offset + done));
    if (got < 0) {
      if (errno == EINTR) continue;
      throw MapIoError("cannot read map file '" + path_ + "': " + errnoText());
    }
    if (got == 0) {
      throw MapIoError("map file '" + path_ + "' rejected: it shrank while being read");
    }
    done += static_cast<std::size_t>(got);
  }
  return out;
}

}  // namespace detail
}  // namespace wavog
