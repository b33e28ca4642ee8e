// dynamic_reconfigure <-> Config: the one mapping between the run-time parameters of
// cfg/Mapping.cfg and the configuration, both ways (the server's start values, a change, the
// values handed back when a change is refused). Stateless functions: thread-safe.
#ifndef WAVOG_MAPPING_SRC_ROS_RECONFIGURE_H_
#define WAVOG_MAPPING_SRC_ROS_RECONFIGURE_H_

#include <string>
#include <vector>

#include "wavog_mapping/MappingConfig.h"
#include "wavog_mapping/ros/config.h"

namespace wavog_ros {

/// The run-time parameters of `config`, for the reconfigure server and its clients.
wavog_mapping::MappingConfig toReconfigure(const Config& config);

/// `config` with the run-time parameters of `rc` (policy, sensor model, publish_rate, scales).
/// Every violation, checked by the same validate() as at start-up, is appended to *errors; the
/// result must not be used then.
Config withReconfigure(const Config& config, const wavog_mapping::MappingConfig& rc,
                       std::vector<std::string>* errors);

/// Parses "2, 3,4" into scales; false on a malformed entry.
bool parseScales(const std::string& text, std::vector<int>* scales);
/// "2,3,4".
std::string joinScales(const std::vector<int>& scales);

}  // namespace wavog_ros

#endif  // WAVOG_MAPPING_SRC_ROS_RECONFIGURE_H_
