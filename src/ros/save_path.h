// Where ~save_map may write: below map_dir only. A relative path resolves under it; '..' and
// anything whose existing part leads (through symlinks) outside it are refused. Stateless
// functions of the file system: reentrant.
#ifndef WAVOG_MAPPING_SRC_ROS_SAVE_PATH_H_
#define WAVOG_MAPPING_SRC_ROS_SAVE_PATH_H_

#include <string>

namespace wavog_ros {

/// The ROS home: $ROS_HOME, else $HOME/.ros (else /tmp/.ros without a HOME).
std::string rosHome();

/// The file ~save_map writes for `path` under `dir` (map_dir; empty: rosHome()). Returns false
/// with *error saying why it is refused: empty, a '..' component, or outside `dir` (lexically, or
/// once the symlinks of its existing directories are followed). Never throws.
bool resolveSavePath(const std::string& dir, const std::string& path, std::string* resolved,
                     std::string* error);

}  // namespace wavog_ros

#endif  // WAVOG_MAPPING_SRC_ROS_SAVE_PATH_H_
