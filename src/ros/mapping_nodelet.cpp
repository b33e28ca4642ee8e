// The mapper as a nodelet: a thin wrapper over MappingRos on the multi-threaded node handles.
#include <nodelet/nodelet.h>

#include <memory>
#include <pluginlib/class_list_macros.hpp>

#include "wavog_mapping/ros/mapping_ros.h"

namespace wavog_ros {

class MappingNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      mapper_ = std::make_unique<MappingRos>(getMTNodeHandle(), getMTPrivateNodeHandle());
    } catch (const std::exception& e) {
      // The loader swallows the exception's text: say it here, then fail the load.
      NODELET_FATAL("%s", e.what());
      throw;
    }
  }

  std::unique_ptr<MappingRos> mapper_;
};

}  // namespace wavog_ros

PLUGINLIB_EXPORT_CLASS(wavog_ros::MappingNodelet, nodelet::Nodelet)
