// The mapper as a standalone node: the same MappingRos as the nodelet, callbacks on 4 threads.
// Exits 1 on a bad configuration or map_file, after a message naming the parameter.
#include <ros/ros.h>

#include <exception>

#include "wavog_mapping/ros/mapping_ros.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "wavog_mapping");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  try {
    wavog_ros::MappingRos mapper(nh, pnh);
    ros::MultiThreadedSpinner spinner(4);
    spinner.spin();
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", ros::this_node::getName().c_str(), e.what());
    // Stop roscpp's threads before the statics they use are destroyed.
    ros::shutdown();
    return 1;
  }
  return 0;
}
