// wavog_fleet as a nodelet: MappingRos in the fleet role on the multi-threaded node handles.
#include <nodelet/nodelet.h>

#include <memory>
#include <pluginlib/class_list_macros.hpp>

#include "wavog_mapping/ros/mapping_ros.h"

namespace wavog_ros {

class FleetNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      fleet_ = std::make_unique<MappingRos>(getMTNodeHandle(), getMTPrivateNodeHandle(),
                                            MapperRole::kFleet);
    } catch (const std::exception& e) {
      NODELET_FATAL("%s", e.what());
      throw;
    }
  }

  std::unique_ptr<MappingRos> fleet_;
};

}  // namespace wavog_ros

PLUGINLIB_EXPORT_CLASS(wavog_ros::FleetNodelet, nodelet::Nodelet)
