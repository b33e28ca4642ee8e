# Simulation, scenario and policy evaluation (issue 5): wavog_sim (ROS-free: std + Eigen +
# yaml-cpp), wavog_simulate (rosbag writer), wavog_evaluate, and their gtests (ctest label "sim").

# Static: the installed tools then need no extra shared library.
add_library(wavog_sim STATIC
  src/sim/geometry.cpp src/sim/world.cpp src/sim/world_file.cpp src/sim/laser_sim.cpp
  src/sim/ground_truth.cpp src/sim/pose_noise.cpp src/sim/wall_metrics.cpp)
target_link_libraries(wavog_sim PUBLIC wavog_core PRIVATE yaml-cpp)
target_include_directories(wavog_sim SYSTEM PUBLIC ${EIGEN3_INCLUDE_DIR})
target_compile_options(wavog_sim PRIVATE ${WAVOG_WARNINGS})
set_target_properties(wavog_sim PROPERTIES POSITION_INDEPENDENT_CODE ON)

function(wavog_sim_test name)
  add_executable(${name} test/sim/${name}.cpp)
  target_link_libraries(${name} PRIVATE ${ARGN} GTest::GTest GTest::Main)
  target_compile_options(${name} PRIVATE ${WAVOG_WARNINGS})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  add_test(NAME sim_${name} COMMAND ${name}
           --gtest_output=xml:${CMAKE_BINARY_DIR}/test_results/sim/${name}.xml)
  set_tests_properties(sim_${name} PROPERTIES LABELS "sim" TIMEOUT 300)
endfunction()

# Policy evaluation through the core map (links wavog_core for real).
add_library(wavog_sim_eval STATIC src/sim/evaluation.cpp src/sim/noise_study.cpp)
target_link_libraries(wavog_sim_eval PUBLIC wavog_sim wavog_core
                      PRIVATE nlohmann_json::nlohmann_json Threads::Threads)
target_compile_options(wavog_sim_eval PRIVATE ${WAVOG_WARNINGS})

wavog_sim_test(test_simulator wavog_sim)
wavog_sim_test(test_policy_response wavog_sim_eval)
wavog_sim_test(test_pose_noise wavog_sim_eval)
wavog_sim_test(test_ndt_walls wavog_sim_eval)

# ---- wavog_simulate: scenario -> rosbag (rosbag C++ API, no roscore) --------------------------
set(WAVOG_SIM_BIN_DIR ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
add_executable(wavog_simulate src/tools/simulate.cpp src/ros/fleet/range_codec.cpp)
target_include_directories(wavog_simulate SYSTEM PRIVATE ${catkin_INCLUDE_DIRS})
target_include_directories(wavog_simulate PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/ros)
target_link_libraries(wavog_simulate PRIVATE wavog_sim wavog_io wavog_tool_support ${catkin_LIBRARIES})
target_compile_options(wavog_simulate PRIVATE ${WAVOG_WARNINGS})
set_target_properties(wavog_simulate PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${WAVOG_SIM_BIN_DIR})
if(TARGET ${PROJECT_NAME}_generate_messages_cpp)  # --placed-scans writes PlacedScan
  add_dependencies(wavog_simulate ${PROJECT_NAME}_generate_messages_cpp)
endif()

# ---- wavog_evaluate: every policy over a scenario against ground truth (no ROS at run time) ---
add_executable(wavog_evaluate src/tools/evaluate.cpp src/tools/evaluate_output.cpp)
target_link_libraries(wavog_evaluate PRIVATE wavog_sim_eval wavog_io wavog_tool_support Threads::Threads)
target_compile_options(wavog_evaluate PRIVATE ${WAVOG_WARNINGS})
set_target_properties(wavog_evaluate PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${WAVOG_SIM_BIN_DIR})

# The bag end to end (rosbag API; maps it with wavog_offline when that is built).
wavog_sim_test(test_simulate_bag wavog_sim)
target_include_directories(test_simulate_bag SYSTEM PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_simulate_bag PRIVATE ${catkin_LIBRARIES})
target_compile_definitions(test_simulate_bag PRIVATE
  WAVOG_SIMULATE="$<TARGET_FILE:wavog_simulate>" WAVOG_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
add_dependencies(test_simulate_bag wavog_simulate)
if(TARGET wavog_offline)
  target_compile_definitions(test_simulate_bag PRIVATE WAVOG_OFFLINE="$<TARGET_FILE:wavog_offline>")
  add_dependencies(test_simulate_bag wavog_offline)
endif()
