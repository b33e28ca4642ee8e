# wavog_static_tf (src/static_tf): one latched transform on /tf_static, for a robot or a bag
# without tf for its laser (launch argument fixed_frame_laser). Debian has no
# static_transform_publisher. Included when ROS is built.
add_executable(wavog_static_tf src/static_tf/static_tf.cpp)
target_include_directories(wavog_static_tf SYSTEM PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(wavog_static_tf PRIVATE ${catkin_LIBRARIES})
target_compile_options(wavog_static_tf PRIVATE ${WAVOG_WARNINGS})
set_target_properties(wavog_static_tf PROPERTIES
  RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
