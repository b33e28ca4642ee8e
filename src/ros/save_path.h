// Where ~save_map may write: below map_dir only (the ROS home when empty, not the working
// directory). A relative path resolves under it, an absolute path below it is taken as it is;
// '..' and anything whose existing part leads (through symlinks) outside it are refused. Stateless
// functions of the file system: reentrant.
#ifndef WAVOG_MAPPING_SRC_ROS_SAVE_PATH_H_
#define WAVOG_MAPPING_SRC_ROS_SAVE_PATH_H_

#include <string>
#include <vector>

namespace wavog_ros {

/// The ROS home: $ROS_HOME, else $HOME/.ros (else /tmp/.ros without a HOME).
std::string rosHome();

/// The file ~save_map writes for `path` under `dir` (map_dir; empty: rosHome()), an absolute
/// path. Accepted: a relative path (below `dir`), an absolute path below `dir` as written or once
/// the symlinks of both are followed. Returns false with *error saying why it is refused (naming
/// `dir` as an absolute path): empty, a '..' component, or outside `dir` (lexically, or once the
/// symlinks of its existing directories are followed). Never throws.
bool resolveSavePath(const std::string& dir, const std::string& path, std::string* resolved,
                     std::string* error);

/// ~save_map's answer for the files it wrote (absolute paths, the map file first): "saved N files
/// in <its folder>: <name> <name> ...", so that a caller sees where a relative path went.
std::string savedMessage(const std::vector<std::string>& files);

}  // namespace wavog_ros

#endif  // WAVOG_MAPPING_SRC_ROS_SAVE_PATH_H_
