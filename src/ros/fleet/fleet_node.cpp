// wavog_fleet as a standalone node: MappingRos in the fleet role (the vehicles' PlacedScan streams
// listed in fleet_vehicles), callbacks on 4 threads. Exits 1 on a bad configuration or map_file.
#include <ros/ros.h>

#include <exception>

#include "wavog_mapping/ros/mapping_ros.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "wavog_fleet");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  try {
    wavog_ros::MappingRos fleet(nh, pnh, wavog_ros::MapperRole::kFleet);
    ros::MultiThreadedSpinner spinner(4);
    spinner.spin();
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", ros::this_node::getName().c_str(), e.what());
    ros::shutdown();
    return 1;
  }
  return 0;
}
