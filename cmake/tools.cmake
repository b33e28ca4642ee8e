# Offline tools (issue 4): wavog_log2bag (CARMEN log -> rosbag) and wavog_offline (bag or CARMEN
# log -> maps, no roscore), with their tests (ctest label "tools"). Included when ROS is built.
set(WAVOG_TOOLS_BIN_DIR ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})

add_library(wavog_tool_support STATIC src/tools/tool_support.cpp)
target_link_libraries(wavog_tool_support PUBLIC wavog_io wavog_core)
target_include_directories(wavog_tool_support PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/src/tools)
target_compile_options(wavog_tool_support PRIVATE ${WAVOG_WARNINGS})

add_executable(wavog_log2bag src/tools/log2bag.cpp)
target_include_directories(wavog_log2bag SYSTEM PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(wavog_log2bag PRIVATE wavog_tool_support ${catkin_LIBRARIES})
target_compile_options(wavog_log2bag PRIVATE ${WAVOG_WARNINGS})
set_target_properties(wavog_log2bag PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${WAVOG_TOOLS_BIN_DIR})

if(TARGET wavog_ros_config AND EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/src/tools/offline.cpp)
  add_executable(wavog_offline src/tools/offline.cpp)
  target_include_directories(wavog_offline SYSTEM PRIVATE ${catkin_INCLUDE_DIRS})
  target_link_libraries(wavog_offline PRIVATE wavog_tool_support wavog_ros_config ${catkin_LIBRARIES})
  target_compile_options(wavog_offline PRIVATE ${WAVOG_WARNINGS})
  set_target_properties(wavog_offline PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${WAVOG_TOOLS_BIN_DIR})
  install(TARGETS wavog_offline RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
endif()
install(TARGETS wavog_log2bag RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

# ---- Tests: plain gtest executables (built by `make`, unlike catkin_add_gtest) run by ctest ----
find_package(GTest REQUIRED)

function(wavog_tools_test name)
  add_executable(${name} test/tools/${name}.cpp ${ARGN})
  target_link_libraries(${name} PRIVATE wavog_tool_support GTest::GTest GTest::Main)
  target_compile_options(${name} PRIVATE ${WAVOG_WARNINGS})
  target_compile_definitions(${name} PRIVATE WAVOG_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  add_test(NAME tools_${name}
           COMMAND ${name} --gtest_output=xml:${CMAKE_BINARY_DIR}/test_results/tools/${name}.xml
           WORKING_DIRECTORY ${CMAKE_BINARY_DIR})
  set_tests_properties(tools_${name} PROPERTIES LABELS "tools" TIMEOUT 300)
endfunction()

wavog_tools_test(test_image_io)
wavog_tools_test(test_tool_support)

if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/test/tools/test_log2bag.cpp)
  wavog_tools_test(test_log2bag)
  target_include_directories(test_log2bag SYSTEM PRIVATE ${catkin_INCLUDE_DIRS})
  target_link_libraries(test_log2bag PRIVATE ${catkin_LIBRARIES})
  target_compile_definitions(test_log2bag PRIVATE WAVOG_LOG2BAG="$<TARGET_FILE:wavog_log2bag>")
  add_dependencies(test_log2bag wavog_log2bag)
endif()

if(TARGET wavog_offline AND EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/test/tools/test_offline.cpp)
  wavog_tools_test(test_offline)
  target_include_directories(test_offline SYSTEM PRIVATE ${catkin_INCLUDE_DIRS})
  target_link_libraries(test_offline PRIVATE wavog_ros_config ${catkin_LIBRARIES})
  target_compile_definitions(test_offline PRIVATE
    WAVOG_LOG2BAG="$<TARGET_FILE:wavog_log2bag>" WAVOG_OFFLINE="$<TARGET_FILE:wavog_offline>")
  add_dependencies(test_offline wavog_log2bag wavog_offline)
endif()

if(CATKIN_ENABLE_TESTING AND EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/test/tools/playback.test)
  find_package(rostest REQUIRED)
  add_rostest(test/tools/playback.test DEPENDENCIES wavog_log2bag wavog_offline)
endif()
