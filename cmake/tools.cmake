# Offline tools (issue 4): wavog_log2bag (CARMEN log -> rosbag) and wavog_offline (bag or CARMEN
# log -> maps, no roscore), with their tests (ctest label "tools"). Included when ROS is built.
set(WAVOG_TOOLS_BIN_DIR ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
# The shared data the tool tests read: WAVOG_DATA_DIR (cmake/real_data.cmake).
set(_wavog_data_dir ${WAVOG_DATA_DIR})

add_executable(wavog_log2bag src/tools/log2bag.cpp)
target_include_directories(wavog_log2bag SYSTEM PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(wavog_log2bag PRIVATE wavog_tool_support ${catkin_LIBRARIES})
target_compile_options(wavog_log2bag PRIVATE ${WAVOG_WARNINGS})
set_target_properties(wavog_log2bag PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${WAVOG_TOOLS_BIN_DIR})

if(TARGET wavog_ros AND EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/src/tools/offline.cpp)
  add_executable(wavog_offline src/tools/offline.cpp src/tools/offline_inputs.cpp)
  target_include_directories(wavog_offline SYSTEM PRIVATE ${catkin_INCLUDE_DIRS})
  target_link_libraries(wavog_offline PRIVATE wavog_tool_support wavog_ros ${catkin_LIBRARIES})
  target_compile_options(wavog_offline PRIVATE ${WAVOG_WARNINGS})
  set_target_properties(wavog_offline PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${WAVOG_TOOLS_BIN_DIR})
endif()

# ---- Tests: plain gtest executables (built by `make`, unlike catkin_add_gtest) run by ctest ----

# wavog_tools_test(<name> [REAL_DATA <file>...]): as wavog_core_test (cmake/core_tests.cmake).
function(wavog_tools_test name)
  cmake_parse_arguments(ARG "" "" "REAL_DATA" ${ARGN})
  add_executable(${name} test/tools/${name}.cpp)
  target_link_libraries(${name} PRIVATE wavog_tool_support GTest::GTest GTest::Main ZLIB::ZLIB)
  target_compile_options(${name} PRIVATE ${WAVOG_WARNINGS})
  target_compile_definitions(${name} PRIVATE WAVOG_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
  target_include_directories(${name} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/test/core)  # synthetic_log.h
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  wavog_add_gtest(tools_${name} ${name} ${CMAKE_BINARY_DIR}/test_results/tools tools 300
                  "${ARG_REAL_DATA}")
endfunction()

wavog_tools_test(test_image_io)
# The PNG test decodes with Python's PIL (python3-pil), independent of libpng.
find_package(Python3 COMPONENTS Interpreter REQUIRED)
target_compile_definitions(test_image_io PRIVATE WAVOG_PYTHON="${Python3_EXECUTABLE}")
wavog_tools_test(test_tool_support)
wavog_tools_test(test_ndt_image)

if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/test/tools/test_log2bag.cpp)
  wavog_tools_test(test_log2bag REAL_DATA fr079-corrected.log.gz csail-robotlaser1.log.gz)
  target_include_directories(test_log2bag SYSTEM PRIVATE ${catkin_INCLUDE_DIRS})
  target_link_libraries(test_log2bag PRIVATE ${catkin_LIBRARIES})
  target_compile_definitions(test_log2bag PRIVATE WAVOG_LOG2BAG="$<TARGET_FILE:wavog_log2bag>")
  add_dependencies(test_log2bag wavog_log2bag)
endif()

if(TARGET wavog_offline AND EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/test/tools/test_offline.cpp)
  wavog_tools_test(test_offline REAL_DATA fr079-corrected.log.gz laser_scan_matcher_demo.bag)
  target_include_directories(test_offline SYSTEM PRIVATE ${catkin_INCLUDE_DIRS})
  target_link_libraries(test_offline PRIVATE wavog_ros ${catkin_LIBRARIES})
  target_compile_definitions(test_offline PRIVATE
    WAVOG_LOG2BAG="$<TARGET_FILE:wavog_log2bag>" WAVOG_OFFLINE="$<TARGET_FILE:wavog_offline>")
  add_dependencies(test_offline wavog_log2bag wavog_offline)
endif()

# Playback rostest: the first 300 scans of fr079 converted (fixture tools_playback_bag), played
# through launch/playback.launch into the node, compared with wavog_offline's map.
if(CATKIN_ENABLE_TESTING AND TARGET wavog_offline AND TARGET wavog_mapping_node
   AND EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/test/tools/playback.test)
  wavog_real_data_found(_wavog_have_fr079 rostest_playback.test fr079-corrected.log.gz)
  if(_wavog_have_fr079)
    add_executable(test_playback test/tools/test_playback.cpp)
    target_link_libraries(test_playback PRIVATE wavog_ros_config wavog_core ${catkin_LIBRARIES}
                          GTest::GTest)
    target_compile_options(test_playback PRIVATE ${WAVOG_WARNINGS})
    target_compile_definitions(test_playback PRIVATE WAVOG_OFFLINE="$<TARGET_FILE:wavog_offline>")
    set_target_properties(test_playback PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${WAVOG_TOOLS_BIN_DIR})
    add_dependencies(test_playback ${PROJECT_NAME}_generate_messages_cpp wavog_offline)

    set(_wavog_playback_bag ${CMAKE_BINARY_DIR}/test_data/playback_fr079_300.bag)
    add_test(NAME tools_playback_bag
             COMMAND sh -c "mkdir -p ${CMAKE_BINARY_DIR}/test_data && $<TARGET_FILE:wavog_log2bag> --quiet --max-scans 300 --pad 100 ${_wavog_data_dir}/fr079-corrected.log.gz ${_wavog_playback_bag}")
    set_tests_properties(tools_playback_bag PROPERTIES FIXTURES_SETUP wavog_playback_bag
                         LABELS "tools" TIMEOUT 60)
    # The bag's path reaches the launch file through the environment (rostest ARGS would end up
    # in the test's name).
    add_rostest(test/tools/playback.test DEPENDENCIES test_playback wavog_mapping_node wavog_offline)
    set_tests_properties(_ctest_${PROJECT_NAME}_rostest_test_tools_playback.test PROPERTIES
                         FIXTURES_REQUIRED wavog_playback_bag LABELS "tools;rostest" TIMEOUT 300
                         ENVIRONMENT "WAVOG_PLAYBACK_BAG=${_wavog_playback_bag}")
    # The same playback with the bag's /tf handed on in bursts (issue 42).
    add_rostest(test/tools/playback_tf_bursts.test
                DEPENDENCIES test_playback wavog_mapping_node wavog_offline)
    set_tests_properties(_ctest_${PROJECT_NAME}_rostest_test_tools_playback_tf_bursts.test
                         PROPERTIES FIXTURES_REQUIRED wavog_playback_bag LABELS "tools;rostest"
                         TIMEOUT 300 ENVIRONMENT "WAVOG_PLAYBACK_BAG=${_wavog_playback_bag}")
  endif()
endif()

# Real-bag rostest: the laser_scan_matcher demo bag (another project's driver: frame_id '/laser',
# no tf), played through launch/playback.launch with fixed_frame_laser:=true.
if(CATKIN_ENABLE_TESTING AND TARGET wavog_mapping_node
   AND EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/test/tools/real_bag.test)
  set(_wavog_real_bag ${_wavog_data_dir}/laser_scan_matcher_demo.bag)
  wavog_real_data_found(_wavog_have_lsm rostest_real_bag.test laser_scan_matcher_demo.bag)
  if(_wavog_have_lsm)
    add_executable(test_real_bag test/tools/test_real_bag.cpp)
    target_link_libraries(test_real_bag PRIVATE wavog_ros_includes ${catkin_LIBRARIES} GTest::GTest)
    target_compile_options(test_real_bag PRIVATE ${WAVOG_WARNINGS})
    set_target_properties(test_real_bag PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${WAVOG_TOOLS_BIN_DIR})
    add_dependencies(test_real_bag ${PROJECT_NAME}_generate_messages_cpp)
    add_rostest(test/tools/real_bag.test DEPENDENCIES test_real_bag wavog_mapping_node wavog_static_tf)
    set_tests_properties(_ctest_${PROJECT_NAME}_rostest_test_tools_real_bag.test PROPERTIES
                         LABELS "tools;rostest" TIMEOUT 200
                         ENVIRONMENT "WAVOG_REAL_BAG=${_wavog_real_bag}")
  endif()
endif()

# ---- wavog_paper (issue 17): the paper's figures from fr079 (make paper; no ROS at run time) ---
add_executable(wavog_paper src/tools/paper.cpp)
target_link_libraries(wavog_paper PRIVATE wavog_sim wavog_io wavog_tool_support CLI11::CLI11
                      nlohmann_json::nlohmann_json Threads::Threads)
target_compile_options(wavog_paper PRIVATE ${WAVOG_WARNINGS})
set_target_properties(wavog_paper PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${WAVOG_TOOLS_BIN_DIR})
