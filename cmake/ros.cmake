# ROS layer: parameter loader, mapper (nodelet + node), rostests. Owned by the ROS layer.
# Include paths are per target: ROS headers are SYSTEM, and wavog_core never sees them.
# wavog_ros_includes carries them: ROS's headers and the generated ones (messages, services,
# dynamic_reconfigure in the devel space), as SYSTEM includes, so the warning flags never apply to
# generated code. Every ROS target links it (wavog_ros_config passes it on).
add_library(wavog_ros_includes INTERFACE)
# catkin_lint: the devel space's include folder is catkin's own (gencpp adds it too, not SYSTEM).
#catkin_lint: ignore_once EXTERNAL_DIRECTORY EXTERNAL_INTERFACE_PATH
target_include_directories(wavog_ros_includes SYSTEM INTERFACE ${catkin_INCLUDE_DIRS}
                           ${CATKIN_DEVEL_PREFIX}/${CATKIN_GLOBAL_INCLUDE_DESTINATION})

# ---- wavog_ros_config: the one parameter loader (node, nodelet and offline tools) -------------
add_library(wavog_ros_config src/ros/config.cpp src/ros/config_validate.cpp)
target_link_libraries(wavog_ros_config PUBLIC wavog_ros_includes wavog_core ${catkin_LIBRARIES} PRIVATE yaml-cpp)
target_compile_options(wavog_ros_config PRIVATE ${WAVOG_WARNINGS})
set_target_properties(wavog_ros_config PROPERTIES POSITION_INDEPENDENT_CODE ON)

# ---- wavog_ros: the mapper class (inputs, tf, publication, services, diagnostics) and the scan
# placement it shares with wavog_offline ---------------------------------------------------------
if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/src/ros/mapping_ros.cpp)
  add_library(wavog_ros
    src/ros/conversions.cpp
    src/ros/scan_placement.cpp
    src/ros/tf_messages.cpp
    src/ros/input_status.cpp
    src/ros/pose_check.cpp
    src/ros/map_publisher.cpp
    src/ros/reconfigure.cpp
    src/ros/mapping_ros.cpp
    src/ros/mapping_ros_scans.cpp
    src/ros/mapping_ros_tf_wait.cpp
    src/ros/mapping_ros_publish.cpp
    src/ros/mapping_ros_diagnostics.cpp
    src/ros/mapping_ros_services.cpp
    src/ros/mapping_ros_flush.cpp
    src/ros/save_path.cpp)
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
  # Scan placement (tf -> pose and view) and the dynamic_reconfigure mapping: no master needed.
  if(TARGET wavog_ros)
    catkin_add_gtest(test_scan_placement test/ros/test_scan_placement.cpp)
    if(TARGET test_scan_placement)
      target_link_libraries(test_scan_placement wavog_ros ${GTEST_MAIN_LIBRARIES})
      # tf_messages.h (the node's tf failure texts), a private header of src/ros.
      target_include_directories(test_scan_placement PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/ros)
    endif()
    # The file names and crop shared by ~save_map and wavog_offline (wavog_io).
    catkin_add_gtest(test_map_files test/ros/test_map_files.cpp)
    if(TARGET test_map_files)
      target_link_libraries(test_map_files wavog_io ${GTEST_MAIN_LIBRARIES})
    endif()
    catkin_add_gtest(test_reconfigure test/ros/test_reconfigure.cpp)
    if(TARGET test_reconfigure)
      target_link_libraries(test_reconfigure wavog_ros ${GTEST_MAIN_LIBRARIES})
      add_dependencies(test_reconfigure ${PROJECT_NAME}_gencfg)
    endif()
    # Scans lost before the node received them: header.seq gaps, no false counts.
    catkin_add_gtest(test_seq_gaps test/ros/test_seq_gaps.cpp)
    if(TARGET test_seq_gaps)
      target_link_libraries(test_seq_gaps wavog_ros ${GTEST_MAIN_LIBRARIES})
    endif()
    # The inputs' checking deserialiser: forged array lengths refused before sizing (issue 42).
    catkin_add_gtest(test_checked_deserialize test/ros/test_checked_deserialize.cpp)
    if(TARGET test_checked_deserialize)
      target_include_directories(test_checked_deserialize PRIVATE
                                 ${CMAKE_CURRENT_SOURCE_DIR}/src/ros ${CMAKE_CURRENT_SOURCE_DIR}/test/ros)
      target_link_libraries(test_checked_deserialize wavog_ros ${GTEST_MAIN_LIBRARIES})
    endif()
    # Absurd poses from tf (issue 27) and other people's scan geometry: no master needed.
    catkin_add_gtest(test_pose_check test/ros/test_pose_check.cpp)
    if(TARGET test_pose_check)
      target_link_libraries(test_pose_check wavog_ros ${GTEST_MAIN_LIBRARIES})
    endif()
    catkin_add_gtest(test_scan_geometry test/ros/test_scan_geometry.cpp)
    if(TARGET test_scan_geometry)
      target_link_libraries(test_scan_geometry wavog_ros ${GTEST_MAIN_LIBRARIES})
    endif()
    # The NDT layers as MarkerArray and PointCloud2 (issue 14).
    catkin_add_gtest(test_ndt_conversions test/ros/test_ndt_conversions.cpp)
    if(TARGET test_ndt_conversions)
      target_link_libraries(test_ndt_conversions wavog_ros ${GTEST_MAIN_LIBRARIES})
    endif()
    # The node's limits (issue 16): time checks, publication sizing, save_map below map_dir.
    catkin_add_gtest(test_node_limits test/ros/test_node_limits.cpp)
    if(TARGET test_node_limits)
      target_link_libraries(test_node_limits wavog_ros ${GTEST_MAIN_LIBRARIES})
    endif()
    # A layer too large as a whole is the window around the robot (issue 41); on the campus log.
    add_executable(test_layers test/ros/test_layers.cpp)
    target_link_libraries(test_layers PRIVATE wavog_ros GTest::GTest GTest::Main)
    target_compile_options(test_layers PRIVATE ${WAVOG_WARNINGS})
    set_target_properties(test_layers PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
    wavog_add_gtest(ros_test_layers test_layers ${CMAKE_BINARY_DIR}/test_results/ros ros 600
                    "fr-campus-corrected.log.gz")
  endif()
  # A rostest with its own gtest binary: the node's message headers, catkin's and gtest's
  # libraries, built after the messages and the node.
  function(wavog_rostest_gtest target launch source)
    add_rostest_gtest(${target} ${launch} ${source})
    target_link_libraries(${target} wavog_ros_includes ${catkin_LIBRARIES} ${GTEST_LIBRARIES})
    add_dependencies(${target} ${PROJECT_NAME}_generate_messages_cpp ${WAVOG_ROS_RUNTIME})
  endfunction()

  if(TARGET wavog_mapping_node)
    set(WAVOG_ROS_RUNTIME wavog_mapping_node wavog_mapping_nodelet)

    # Integration: the same gtest against the node and against the nodelet, plus hztests.
    wavog_rostest_gtest(test_mapping_system test/mapping_node.test test/ros/test_mapping_system.cpp)
    add_rostest(test/mapping_nodelet.test DEPENDENCIES test_mapping_system)

    # Bad inputs: every malformed scan counted by reason, the node stays up.
    if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/test/ros/test_bad_input.cpp)
      wavog_rostest_gtest(test_bad_input test/bad_input.test test/ros/test_bad_input.cpp)
    endif()

    # Scans waiting for late tf: pushed out of the tf filter, placed when tf comes, dropped only at
    # the bounds (subscriber_queue_size, tf_cache_time).
    wavog_rostest_gtest(test_tf_wait test/tf_wait.test test/ros/test_tf_wait.cpp)

    # Lost scans: seq gaps counted exactly, seq 0 not counted, a burst fully accounted for.
    wavog_rostest_gtest(test_lost_scans test/ros/lost_scans.test test/ros/test_lost_scans.cpp)

    # Hostile input (issue 16): out-of-range time, huge read-outs, save_map outside map_dir,
    # map_file not a regular file.
    wavog_rostest_gtest(test_hostile_input test/hostile_input.test test/ros/test_hostile_input.cpp)
    target_compile_definitions(test_hostile_input PRIVATE
      WAVOG_NODE_BIN="${CATKIN_DEVEL_PREFIX}/lib/wavog_mapping/wavog_mapping_node")
    target_link_libraries(test_hostile_input wavog_core)  # writes a map file with payloads

    # forget_half_life with inputs of two rates; the reflection layers' topics.
    wavog_rostest_gtest(test_half_life_rates test/half_life_rates.test
      test/ros/test_half_life_rates.cpp)
    wavog_rostest_gtest(test_reflection_topics test/reflection_topics.test
      test/ros/test_reflection_topics.cpp)
    # The NDT layers' topics (ndt: true), none without ndt, a bad ndt_min_weight at start-up.
    wavog_rostest_gtest(test_ndt_topics test/ndt_topics.test test/ros/test_ndt_topics.cpp)
    target_compile_definitions(test_ndt_topics PRIVATE
      WAVOG_NODE_BIN="${CATKIN_DEVEL_PREFIX}/lib/wavog_mapping/wavog_mapping_node")
    # Sim time jumping backwards (bag restart): tf buffer cleared, mapping goes on.
    wavog_rostest_gtest(test_clock_jump test/clock_jump.test test/ros/test_clock_jump.cpp)

    # Motion compensation through ROS: a moving scanner, compensation on and off.
    wavog_rostest_gtest(test_motion test/motion.test test/ros/test_motion.cpp)

    # The end of a played bag: '/' frames, no tf for one laser, last scans after the last tf.
    wavog_rostest_gtest(test_bag_end test/bag_end.test test/ros/test_bag_end.cpp)

    # Live reconfigure of the policy against a core-only map; an invalid change refused.
    add_rostest_gtest(test_reconfigure_policy test/reconfigure_policy.test
                      test/ros/test_reconfigure_policy.cpp)
    target_link_libraries(test_reconfigure_policy wavog_ros ${catkin_LIBRARIES} ${GTEST_LIBRARIES})
    add_dependencies(test_reconfigure_policy ${PROJECT_NAME}_generate_messages_cpp
                     ${WAVOG_ROS_RUNTIME})

    # Services: reset, clear_region, save_map + restart with map_file, corrupted map_file.
    find_program(WAVOG_NODELET_BIN nodelet PATHS /usr/lib/nodelet ${nodelet_PREFIX}/lib/nodelet
                 NO_DEFAULT_PATH)
    if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/test/ros/test_services.cpp)
      wavog_rostest_gtest(test_services test/services.test test/ros/test_services.cpp)
      target_compile_definitions(test_services PRIVATE
        WAVOG_NODE_BIN="${CATKIN_DEVEL_PREFIX}/lib/wavog_mapping/wavog_mapping_node"
        WAVOG_NODELET_BIN="${WAVOG_NODELET_BIN}")
    endif()

    # The test room as a standalone publisher (make rviz-check, publish_rate.test).
    add_executable(room_scene test/ros/room_scene.cpp)
    target_link_libraries(room_scene wavog_ros_includes ${catkin_LIBRARIES})
    set_target_properties(room_scene PROPERTIES
      RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
    add_rostest(test/publish_rate.test DEPENDENCIES room_scene)

    # Every launch file parses and names existing nodes.
    roslaunch_add_file_check(launch IGNORE_UNSET_ARGS DEPENDENCIES ${WAVOG_ROS_RUNTIME})
  endif()
endif()
