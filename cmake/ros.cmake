# ROS layer: parameter loader, mapper (nodelet + node), rostests. Owned by the ROS layer.
# Include paths are per target: ROS headers are SYSTEM, and wavog_core never sees them.
set(WAVOG_ROS_INCLUDES ${catkin_INCLUDE_DIRS} ${CATKIN_DEVEL_PREFIX}/${CATKIN_GLOBAL_INCLUDE_DESTINATION})

# ---- wavog_ros_config: the one parameter loader (node, nodelet and offline tools) -------------
add_library(wavog_ros_config src/ros/config.cpp)
target_include_directories(wavog_ros_config SYSTEM PUBLIC ${WAVOG_ROS_INCLUDES})
target_link_libraries(wavog_ros_config PUBLIC wavog_core ${catkin_LIBRARIES} PRIVATE yaml-cpp)
target_compile_options(wavog_ros_config PRIVATE ${WAVOG_WARNINGS})
set_target_properties(wavog_ros_config PROPERTIES POSITION_INDEPENDENT_CODE ON)

# ---- wavog_ros: the mapper class (inputs, tf, publication, services, diagnostics) ------------
if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/src/ros/mapping_ros.cpp)
  add_library(wavog_ros src/ros/mapping_ros.cpp src/ros/conversions.cpp)
  target_include_directories(wavog_ros SYSTEM PUBLIC ${WAVOG_ROS_INCLUDES})
  target_link_libraries(wavog_ros PUBLIC wavog_ros_config wavog_io wavog_core ${catkin_LIBRARIES})
  target_compile_options(wavog_ros PRIVATE ${WAVOG_WARNINGS})
  set_target_properties(wavog_ros PROPERTIES POSITION_INDEPENDENT_CODE ON)
  add_dependencies(wavog_ros ${PROJECT_NAME}_generate_messages_cpp ${PROJECT_NAME}_gencfg)

  add_library(wavog_mapping_nodelet src/ros/mapping_nodelet.cpp)
  target_link_libraries(wavog_mapping_nodelet PRIVATE wavog_ros)
  target_compile_options(wavog_mapping_nodelet PRIVATE ${WAVOG_WARNINGS})

  add_executable(wavog_mapping_node src/ros/mapping_node.cpp)
  target_link_libraries(wavog_mapping_node PRIVATE wavog_ros)
  target_compile_options(wavog_mapping_node PRIVATE ${WAVOG_WARNINGS})
endif()

# ---- Tests ------------------------------------------------------------------------------------
if(CATKIN_ENABLE_TESTING)
  # Loader test: no master needed.
  catkin_add_gtest(test_ros_config test/ros/test_config.cpp)
  if(TARGET test_ros_config)
    target_link_libraries(test_ros_config wavog_ros_config ${GTEST_MAIN_LIBRARIES})
    target_compile_definitions(test_ros_config PRIVATE WAVOG_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
  endif()
  include(cmake/ros_tests.cmake OPTIONAL)
endif()
