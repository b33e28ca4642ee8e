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
  std::error_code ec;
  // Absolute (a relative $ROS_HOME is the node's working directory's).
  const fs::path dir = fs::absolute(fs::path(dir_text), ec).lexically_normal();
  if (ec) {
    *error = where + ": " + ec.message();
    return false;
  }
  const fs::path full = (given.is_absolute() ? given : dir / given).lexically_normal();
  // The existing part, symlinks followed, must stay below the directory (itself resolved).
  const fs::path real_dir = fs::weakly_canonical(dir, ec);
  const fs::path real_full = ec ? fs::path() : fs::weakly_canonical(full, ec);
  if (ec) {
    *error = "path '" + path + "': " + ec.message();
    return false;
  }
  // An absolute path names a file below map_dir as written, or once the symlinks of both are
  // followed (map_dir through a symlink, the path by its real folder, or the other way round).
  const bool below = isBelow(full, dir) || (given.is_absolute() && isBelow(real_full, real_dir));
  if (!full.has_filename() || full == dir || real_full == real_dir || !below) {
    *error = "path '" + path + "' is not a file below " + where + " (" + dir.string() +
             "; a relative path is taken below it): refused";
    return false;
  }
  if (!isBelow(real_full, real_dir)) {
    *error = "path '" + path + "' leads to '" + real_full.string() + "' (through a symlink), outside " +
             where + ": refused";
    return false;
  }
  *resolved = full.string();
  return true;
}

std::string savedMessage(const std::vector<std::string>& files) {
  std::string text =
      "saved " + std::to_string(files.size()) + (files.size() == 1 ? " file" : " files");
  if (files.empty()) return text;
  text += " in " + fs::path(files[0]).parent_path().string() + ":";
  for (const std::string& f : files) text += " " + fs::path(f).filename().string();
  return text;
}

}  // namespace wavog_ros
