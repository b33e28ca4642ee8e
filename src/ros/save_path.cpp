// ~save_map's target directory check (see save_path.h).
#include "save_path.h"

#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace wavog_ros {
namespace {

namespace fs = std::filesystem;

/// True when `p` is `dir` or lies below it (both normalised, absolute).
bool isBelow(const fs::path& p, const fs::path& dir) {
  auto d = dir.begin();
  auto i = p.begin();
  for (; d != dir.end(); ++d, ++i) {
    if (d->empty()) continue;  // the empty last element of a path ending in '/'
    if (i == p.end() || *i != *d) return false;
  }
  return true;
}

}  // namespace

std::string rosHome() {
  const char* ros_home = std::getenv("ROS_HOME");
  if (ros_home != nullptr && ros_home[0] != '\0') return ros_home;
  const char* home = std::getenv("HOME");
  return std::string(home != nullptr && home[0] != '\0' ? home : "/tmp") + "/.ros";
}

bool resolveSavePath(const std::string& dir_name, const std::string& path, std::string* resolved,
                     std::string* error) {
  const std::string dir_text = dir_name.empty() ? rosHome() : dir_name;
  const std::string where = "map_dir '" + dir_text + "'";
  if (path.empty()) {
    *error = "path is empty";
    return false;
  }
  const fs::path given(path);
  for (const fs::path& part : given) {
    if (part == "..") {
      *error = "path '" + path + "' has a '..' component: refused (the map is saved below " +
               where + ")";
      return false;
    }
  }
  const fs::path dir = fs::path(dir_text).lexically_normal();
  const fs::path full = (given.is_absolute() ? given : dir / given).lexically_normal();
  if (!full.has_filename() || full == dir || !isBelow(full, dir)) {
    *error = "path '" + path + "' is not a file below " + where + ": refused";
    return false;
  }
  // The existing part, symlinks followed, must stay below the directory (itself resolved).
  std::error_code ec;
  const fs::path real_dir = fs::weakly_canonical(dir, ec);
  const fs::path real_full = ec ? fs::path() : fs::weakly_canonical(full, ec);
  if (ec) {
    *error = "path '" + path + "': " + ec.message();
    return false;
  }
  if (!isBelow(real_full, real_dir) || real_full == real_dir) {
    *error = "path '" + path + "' leads to '" + real_full.string() + "' (through a symlink), outside " +
             where + ": refused";
    return false;
  }
  *resolved = full.string();
  return true;
}

}  // namespace wavog_ros
