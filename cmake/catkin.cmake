# catkin: every ROS component any target of the package needs, messages, and catkin_package().
# Owned by the ROS layer. Everything here must come before the targets that use catkin variables.
find_package(catkin REQUIRED COMPONENTS
  roscpp nodelet pluginlib tf2 tf2_ros tf2_eigen sensor_msgs nav_msgs geometry_msgs map_msgs
  std_msgs std_srvs diagnostic_updater dynamic_reconfigure rosbag message_generation)

catkin_package(
  INCLUDE_DIRS include
  LIBRARIES wavog_core wavog_io
  CATKIN_DEPENDS roscpp nodelet pluginlib tf2 tf2_ros sensor_msgs nav_msgs geometry_msgs map_msgs
                 std_msgs std_srvs diagnostic_updater dynamic_reconfigure rosbag
  DEPENDS EIGEN3
)
