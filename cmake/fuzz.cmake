# libFuzzer harnesses of test/fuzz (make fuzz, mk/fuzz.mk): built only in a tree configured with
# clang and -DWAVOG_FUZZ=ON, whose WAVOG_SANITIZE carries fuzzer-no-link so that the libraries
# under test carry libFuzzer's coverage instrumentation besides ASan and UBSan.
option(WAVOG_FUZZ "Build the libFuzzer harnesses of test/fuzz (clang only)" OFF)
if(WAVOG_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "WAVOG_FUZZ needs clang (libFuzzer), not ${CMAKE_CXX_COMPILER_ID}")
  endif()
  # The dense reference of the core tests (it needs no gtest) and the oracle built on it: checks,
  # not code under test, so without coverage instrumentation (it would dominate the run time).
  add_library(wavog_fuzz_reference STATIC test/core/dense_reference.cpp test/fuzz/reference_oracle.cpp)
  target_link_libraries(wavog_fuzz_reference PUBLIC wavog_core)
  target_include_directories(wavog_fuzz_reference PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/test/core
    ${CMAKE_CURRENT_SOURCE_DIR}/test/fuzz)
  target_compile_options(wavog_fuzz_reference PRIVATE -fno-sanitize=fuzzer-no-link)

  add_custom_target(fuzzers)
  function(wavog_fuzzer name)
    add_executable(${name} test/fuzz/${name}.cpp)
    add_dependencies(fuzzers ${name})
    target_link_libraries(${name} PRIVATE wavog_fuzz_reference wavog_io wavog_core ZLIB::ZLIB)
    target_compile_options(${name} PRIVATE ${WAVOG_WARNINGS} -fsanitize=fuzzer)
    target_link_options(${name} PRIVATE -fsanitize=fuzzer)
    set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/fuzz)
  endfunction()
  wavog_fuzzer(fuzz_map_load)
  wavog_fuzzer(fuzz_carmen)
  wavog_fuzzer(fuzz_integrate)

  # 4: the node's message-to-core path (checkScan, time checks, tf placement, motion
  # compensation, publication sizing) without a roscore: the ROS-layer sources it needs compiled
  # here, against Debian's ROS headers (/usr/include; message structs are header-only) and the
  # libraries of ros::Time and the tf buffer.
  find_library(WAVOG_FUZZ_TF2 tf2)
  find_library(WAVOG_FUZZ_ROSTIME rostime)
  find_library(WAVOG_FUZZ_CONSOLE_BRIDGE console_bridge)
  if(WAVOG_FUZZ_TF2 AND WAVOG_FUZZ_ROSTIME AND WAVOG_FUZZ_CONSOLE_BRIDGE
     AND EXISTS /usr/include/sensor_msgs/LaserScan.h)
    add_library(wavog_fuzz_node_glue STATIC src/ros/conversions.cpp src/ros/scan_placement.cpp)
    target_link_libraries(wavog_fuzz_node_glue PUBLIC wavog_core ${WAVOG_FUZZ_TF2}
      ${WAVOG_FUZZ_ROSTIME} ${WAVOG_FUZZ_CONSOLE_BRIDGE})
    wavog_fuzzer(fuzz_node)
    target_link_libraries(fuzz_node PRIVATE wavog_fuzz_node_glue)

    # 5: the fleet node's message path (intake, checks, reorder buffer, core call): its message
    # headers generated here with Debian's gencpp (this tree has no catkin), its sources compiled
    # against them.
    find_program(WAVOG_FUZZ_PYTHON3 python3 PATHS /usr/bin NO_DEFAULT_PATH)
    if(WAVOG_FUZZ_PYTHON3 AND EXISTS /usr/lib/gencpp/gen_cpp.py
       AND EXISTS /usr/share/std_msgs/msg/Header.msg)
      set(_msgs ${CMAKE_BINARY_DIR}/fuzz_msgs)
      set(_headers)
      foreach(_m PlacedScan VehicleStatus FleetStatus)
        list(APPEND _headers ${_msgs}/wavog_mapping/${_m}.h)
        add_custom_command(OUTPUT ${_msgs}/wavog_mapping/${_m}.h
          COMMAND ${WAVOG_FUZZ_PYTHON3} /usr/lib/gencpp/gen_cpp.py
            ${CMAKE_CURRENT_SOURCE_DIR}/msg/${_m}.msg
            -Iwavog_mapping:${CMAKE_CURRENT_SOURCE_DIR}/msg -Istd_msgs:/usr/share/std_msgs/msg
            -p wavog_mapping -o ${_msgs}/wavog_mapping -e /usr/share/gencpp
          DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/msg/${_m}.msg
          COMMENT "gencpp: ${_m}.h for fuzz_fleet and fuzz_site")
      endforeach()
      add_custom_target(wavog_fuzz_msgs DEPENDS ${_headers})
      add_library(wavog_fuzz_fleet_glue STATIC src/ros/fleet/placed_scan.cpp
        src/ros/fleet/range_codec.cpp src/ros/fleet/intake.cpp)
      add_dependencies(wavog_fuzz_fleet_glue wavog_fuzz_msgs)
      # catkin_lint: the generated headers live in the fuzz tree (made at build time) by design.
      #catkin_lint: ignore_once MISSING_DIRECTORY EXTERNAL_DIRECTORY EXTERNAL_INTERFACE_PATH
      target_include_directories(wavog_fuzz_fleet_glue SYSTEM PUBLIC ${_msgs})
      target_include_directories(wavog_fuzz_fleet_glue PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/src/ros)
      target_link_libraries(wavog_fuzz_fleet_glue PUBLIC wavog_fuzz_node_glue)
      wavog_fuzzer(fuzz_fleet)
      target_link_libraries(fuzz_fleet PRIVATE wavog_fuzz_fleet_glue)

      # 6: wavog_site's parts (site_layers, site_vehicles): the shards' layers and statuses.
      add_library(wavog_fuzz_site_glue STATIC src/ros/fleet/site_layers.cpp
        src/ros/fleet/site_vehicles.cpp)
      add_dependencies(wavog_fuzz_site_glue wavog_fuzz_msgs)
      target_link_libraries(wavog_fuzz_site_glue PUBLIC wavog_fuzz_fleet_glue)
      wavog_fuzzer(fuzz_site)
      target_link_libraries(fuzz_site PRIVATE wavog_fuzz_site_glue)
    else()
      message(WARNING "fuzz_fleet not built: /usr/lib/gencpp/gen_cpp.py or std_msgs missing")
    endif()
  else()
    message(WARNING "fuzz_node not built: Debian's ROS headers or libtf2/librostime missing")
  endif()
endif()
