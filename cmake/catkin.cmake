# catkin: every ROS component any target of the package needs, messages, services,
# dynamic_reconfigure, and catkin_package(). Owned by the ROS layer. Everything here comes before
# the targets that use catkin variables.
find_package(catkin REQUIRED COMPONENTS
  roscpp nodelet pluginlib tf2 tf2_ros sensor_msgs nav_msgs geometry_msgs map_msgs visualization_msgs
  std_msgs std_srvs diagnostic_updater diagnostic_msgs dynamic_reconfigure rosbag message_generation)
find_package(yaml-cpp REQUIRED)

add_message_files(DIRECTORY msg FILES InputStatus.msg MapperStatus.msg)
# The fleet's messages (issue 30: cmake/fleet.cmake).
add_message_files(DIRECTORY msg FILES PlacedScan.msg VehicleStatus.msg FleetStatus.msg)
add_service_files(DIRECTORY srv FILES ClearRegion.srv SaveMap.srv)
generate_messages(DEPENDENCIES std_msgs)
generate_dynamic_reconfigure_options(cfg/Mapping.cfg)

catkin_package(
  INCLUDE_DIRS include
  LIBRARIES wavog_core wavog_io wavog_ros_config
  CATKIN_DEPENDS roscpp nodelet pluginlib tf2 tf2_ros sensor_msgs nav_msgs geometry_msgs map_msgs
                 visualization_msgs std_msgs std_srvs diagnostic_updater diagnostic_msgs dynamic_reconfigure rosbag
                 message_runtime
  DEPENDS EIGEN3
)

# The tests' catkin packages: rostest (add_rostest, add_rostest_gtest) and roslaunch
# (roslaunch_add_file_check), found once here for every fragment.
if(CATKIN_ENABLE_TESTING)
  find_package(rostest REQUIRED)
  find_package(roslaunch REQUIRED)
endif()
