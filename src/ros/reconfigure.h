// dynamic_reconfigure <-> Config: the one mapping between the run-time parameters of
// cfg/Mapping.cfg and the configuration, both ways (the server's start values, a change, the
// values handed back when a change is refused), and the server that refuses an invalid change
// instead of clamping it. The functions are stateless (thread-safe); the server locks itself.
#ifndef WAVOG_MAPPING_SRC_ROS_RECONFIGURE_H_
#define WAVOG_MAPPING_SRC_ROS_RECONFIGURE_H_

#include <dynamic_reconfigure/Reconfigure.h>
#include <ros/ros.h>

#include <functional>
#include <mutex>
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

/// A dynamic_reconfigure server of MappingConfig that refuses a change as a whole. The stock
/// dynamic_reconfigure::Server clamps every value into the .cfg's [min, max] before its callback
/// sees it (odd_occ: -1 arrived as the minimum and was accepted), so an out-of-range value could
/// not be refused. Same protocol (~set_parameters, latched ~parameter_descriptions and
/// ~parameter_updates, values mirrored on the parameter server): dynparam and rqt_reconfigure work
/// unchanged. A refused change fails the call with the reasons (the key as the client names it:
/// `scales`), logs them, and publishes the values in force again: `dynparam set` exits non-zero,
/// rqt_reconfigure shows the old value.
class ReconfigureServer {
 public:
  /// Applies a proposed configuration, or returns why not (one line per violation; empty:
  /// applied). Called with the server's lock held.
  using Apply = std::function<std::vector<std::string>(const wavog_mapping::MappingConfig&)>;

  ReconfigureServer(const ros::NodeHandle& pnh, const wavog_mapping::MappingConfig& initial,
                    Apply apply);
  ReconfigureServer(const ReconfigureServer&) = delete;
  ReconfigureServer& operator=(const ReconfigureServer&) = delete;

 private:
  bool onSet(dynamic_reconfigure::Reconfigure::Request& req,
             dynamic_reconfigure::Reconfigure::Response& res);
  void publishLocked();

  ros::NodeHandle pnh_;
  std::mutex mutex_;
  wavog_mapping::MappingConfig current_;  ///< guarded by mutex_
  Apply apply_;
  ros::Publisher descriptions_pub_, updates_pub_;
  ros::ServiceServer set_srv_;
};

/// Parses "2, 3,4" into scales; false on a malformed entry.
bool parseScales(const std::string& text, std::vector<int>* scales);
/// "2,3,4".
std::string joinScales(const std::vector<int>& scales);

}  // namespace wavog_ros

#endif  // WAVOG_MAPPING_SRC_ROS_RECONFIGURE_H_
