# A fleet's map over the ROS graph (issue 30): the mapper's stream of placed scans and the fleet
# node (wavog_fleet, node and nodelet) join the mapper class wavog_ros; their tests. The messages
# are declared in cmake/catkin.cmake (PlacedScan, VehicleStatus, FleetStatus).
if(NOT TARGET wavog_ros)
  return()
endif()

target_sources(wavog_ros PRIVATE
  src/ros/mapping_ros_fleet.cpp
  src/ros/fleet/placed_scan.cpp
  src/ros/fleet/range_codec.cpp
  src/ros/fleet/intake.cpp
  src/ros/fleet/fleet_stream.cpp
  src/ros/fleet/fleet_receiver.cpp
  src/ros/fleet/vehicle_windows.cpp)

add_library(wavog_fleet_nodelet src/ros/fleet/fleet_nodelet.cpp)
target_link_libraries(wavog_fleet_nodelet PRIVATE wavog_ros)
target_compile_options(wavog_fleet_nodelet PRIVATE ${WAVOG_WARNINGS})

add_executable(wavog_fleet src/ros/fleet/fleet_node.cpp)
target_link_libraries(wavog_fleet PRIVATE wavog_ros)
target_compile_options(wavog_fleet PRIVATE ${WAVOG_WARNINGS})
set_target_properties(wavog_fleet PROPERTIES
  RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})

# wavog_site: the shards' coarse layers put together (issue 36).
add_executable(wavog_site src/ros/fleet/site_node.cpp src/ros/fleet/site_layers.cpp
  src/ros/fleet/site_params.cpp src/ros/fleet/site_vehicles.cpp)
target_link_libraries(wavog_site PRIVATE ${catkin_LIBRARIES})
target_include_directories(wavog_site SYSTEM PRIVATE ${catkin_INCLUDE_DIRS})
target_compile_options(wavog_site PRIVATE ${WAVOG_WARNINGS})
add_dependencies(wavog_site ${PROJECT_NAME}_generate_messages_cpp)
set_target_properties(wavog_site PROPERTIES
  RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  # The merge rule without a master: the reorder buffer, the message checks, and the fleet map
  # equal to one map of every vehicle's scans in stamp order, for every policy.
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/test/ros/test_fleet_merge.cpp AND TARGET wavog_sim)
    catkin_add_gtest(test_fleet_merge test/ros/test_fleet_merge.cpp)
    if(TARGET test_fleet_merge)
      target_include_directories(test_fleet_merge PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/ros)
      target_link_libraries(test_fleet_merge wavog_ros wavog_sim ${GTEST_MAIN_LIBRARIES})
    endif()
  endif()
  # The fleet stream's 16-bit range codes (issue 36).
  catkin_add_gtest(test_range_codec test/ros/test_range_codec.cpp)
  if(TARGET test_range_codec)
    target_include_directories(test_range_codec PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/ros)
    target_link_libraries(test_range_codec wavog_ros ${GTEST_MAIN_LIBRARIES})
  endif()
  # The site node's parts (issue 36): layers put together, hostile layers refused; the vehicles
  # outside every region, the scans mapped by none across shard restarts; its parameters.
  catkin_add_gtest(test_site_layers test/ros/test_site_layers.cpp src/ros/fleet/site_layers.cpp
    src/ros/fleet/site_params.cpp src/ros/fleet/site_vehicles.cpp)
  if(TARGET test_site_layers)
    target_include_directories(test_site_layers PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/ros)
    target_include_directories(test_site_layers SYSTEM PRIVATE ${catkin_INCLUDE_DIRS})
    target_link_libraries(test_site_layers ${catkin_LIBRARIES} ${GTEST_MAIN_LIBRARIES})
    add_dependencies(test_site_layers ${PROJECT_NAME}_generate_messages_cpp)
  endif()
  # A vehicle's window of the fleet map: the same cells wherever its centre falls (issue 42).
  catkin_add_gtest(test_vehicle_windows test/ros/test_vehicle_windows.cpp)
  if(TARGET test_vehicle_windows)
    target_include_directories(test_vehicle_windows PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/ros)
    target_link_libraries(test_vehicle_windows wavog_ros ${GTEST_MAIN_LIBRARIES})
  endif()
  # A vehicle's intake (issue 37): counters, refusals, the index sequence.
  catkin_add_gtest(test_fleet_intake test/ros/test_fleet_intake.cpp)
  if(TARGET test_fleet_intake)
    target_include_directories(test_fleet_intake PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/ros)
    target_link_libraries(test_fleet_intake wavog_ros ${GTEST_MAIN_LIBRARIES})
  endif()
endif()

# ---- The fleet over ROS (test/fleet.test): three simulated vehicles, a bag made at build time ---
if(CATKIN_ENABLE_TESTING AND TARGET wavog_simulate AND TARGET wavog_mapping_node)
  set(WAVOG_FLEET_BAG ${CMAKE_BINARY_DIR}/test_data/fleet3.bag)
  add_custom_command(OUTPUT ${WAVOG_FLEET_BAG}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${CMAKE_BINARY_DIR}/test_data
    COMMAND $<TARGET_FILE:wavog_simulate> --vehicles 3 --duration 28 --seed 5 --out ${WAVOG_FLEET_BAG}
    DEPENDS wavog_simulate
    COMMENT "wavog_simulate: the fleet rostest's bag (3 vehicles, 28 s)")
  add_custom_target(wavog_fleet_test_bag DEPENDS ${WAVOG_FLEET_BAG})  # built with the test
  add_rostest_gtest(test_fleet_system test/fleet.test test/ros/test_fleet_system.cpp)
  target_link_libraries(test_fleet_system wavog_ros wavog_ros_config wavog_sim wavog_core
                        ${catkin_LIBRARIES} ${GTEST_LIBRARIES})
  target_include_directories(test_fleet_system PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/ros)
  target_compile_definitions(test_fleet_system PRIVATE
    WAVOG_FLEET_BAG="${WAVOG_FLEET_BAG}" WAVOG_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}"
    WAVOG_NODE_BIN="${CATKIN_DEVEL_PREFIX}/lib/wavog_mapping/wavog_mapping_node"
    WAVOG_FLEET_BIN="${CATKIN_DEVEL_PREFIX}/lib/wavog_mapping/wavog_fleet")
  add_dependencies(test_fleet_system ${PROJECT_NAME}_generate_messages_cpp wavog_mapping_node
                   wavog_fleet wavog_fleet_nodelet wavog_fleet_test_bag)
endif()

# ---- A vehicle that streams behind the others (test/fleet_lagging.test): waited for, not late ----
if(CATKIN_ENABLE_TESTING AND TARGET wavog_fleet AND TARGET wavog_sim)
  add_rostest_gtest(test_fleet_lagging test/fleet_lagging.test test/ros/test_fleet_lagging.cpp)
  target_link_libraries(test_fleet_lagging wavog_ros wavog_ros_config wavog_sim wavog_core
                        ${catkin_LIBRARIES} ${GTEST_LIBRARIES})
  target_include_directories(test_fleet_lagging PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/ros)
  target_compile_definitions(test_fleet_lagging PRIVATE
    WAVOG_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
  add_dependencies(test_fleet_lagging ${PROJECT_NAME}_generate_messages_cpp wavog_fleet)
endif()

# ---- The fleet map as a nodelet (test/fleet_nodelet.test): placed scans from the test itself ------
if(CATKIN_ENABLE_TESTING AND TARGET wavog_fleet_nodelet)
  add_rostest_gtest(test_fleet_nodelet test/fleet_nodelet.test test/ros/test_fleet_nodelet.cpp)
  target_link_libraries(test_fleet_nodelet wavog_ros_config wavog_core ${catkin_LIBRARIES}
                        ${GTEST_LIBRARIES})
  target_compile_definitions(test_fleet_nodelet PRIVATE WAVOG_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
  add_dependencies(test_fleet_nodelet ${PROJECT_NAME}_generate_messages_cpp wavog_fleet_nodelet)
endif()

# ---- The fleet node's map_metadata and dynamic_map (test/fleet_map_services.test) ----------------
if(CATKIN_ENABLE_TESTING AND TARGET wavog_fleet)
  add_rostest_gtest(test_fleet_map_services test/fleet_map_services.test
                    test/ros/test_fleet_map_services.cpp)
  target_link_libraries(test_fleet_map_services wavog_ros_includes ${catkin_LIBRARIES}
                        ${GTEST_LIBRARIES})
  add_dependencies(test_fleet_map_services ${PROJECT_NAME}_generate_messages_cpp wavog_fleet)
endif()

# ---- Forged array lengths to the mapper and wavog_fleet (test/forged_lengths.test, issue 42) ----
if(CATKIN_ENABLE_TESTING AND TARGET wavog_fleet AND TARGET wavog_mapping_node)
  add_rostest_gtest(test_forged_lengths test/forged_lengths.test test/ros/test_forged_lengths.cpp)
  target_link_libraries(test_forged_lengths wavog_ros_includes ${catkin_LIBRARIES}
                        ${GTEST_LIBRARIES})
  add_dependencies(test_forged_lengths ${PROJECT_NAME}_generate_messages_cpp wavog_fleet
                   wavog_mapping_node)
endif()

# ---- Region shards (test/fleet_shards.test, issue 36): 2 shards, 1 unsharded node, wavog_site ----
if(CATKIN_ENABLE_TESTING AND TARGET wavog_sim)
  add_rostest_gtest(test_fleet_shards test/fleet_shards.test test/ros/test_fleet_shards.cpp)
  target_link_libraries(test_fleet_shards wavog_ros_config wavog_sim wavog_core ${catkin_LIBRARIES}
                        ${GTEST_LIBRARIES})
  target_compile_definitions(test_fleet_shards PRIVATE WAVOG_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}"
    WAVOG_FLEET_BIN="${CATKIN_DEVEL_PREFIX}/lib/wavog_mapping/wavog_fleet")
  add_dependencies(test_fleet_shards ${PROJECT_NAME}_generate_messages_cpp wavog_fleet wavog_site)
endif()
