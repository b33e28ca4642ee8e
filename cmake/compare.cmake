# `make compare` (issue 6): the dense 2D grid baseline, its tests, and the benchmark program that
# runs wavog_core, OctoMap and the baseline side by side. No ROS anywhere here: it also builds with
# -DWAVOG_BUILD_ROS=OFF.

# ---- wavog_baseline: tuned dense grid (std only; uses the core's value types) -------------------
add_library(wavog_baseline src/baseline/dense_grid.cpp)
target_link_libraries(wavog_baseline PUBLIC wavog_core)
target_compile_options(wavog_baseline PRIVATE ${WAVOG_WARNINGS} -Wconversion)
set_target_properties(wavog_baseline PROPERTIES POSITION_INDEPENDENT_CODE ON)

# ---- Baseline unit tests (ctest label "baseline"; no ROS, so they run under the sanitizers) ------
add_executable(test_dense_grid test/baseline/test_dense_grid.cpp)
target_link_libraries(test_dense_grid PRIVATE wavog_baseline GTest::GTest GTest::Main)
target_compile_options(test_dense_grid PRIVATE ${WAVOG_WARNINGS})
set_target_properties(test_dense_grid PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
add_test(NAME baseline_test_dense_grid COMMAND test_dense_grid
  --gtest_output=xml:${CMAKE_BINARY_DIR}/test_results/baseline/test_dense_grid.xml)
set_tests_properties(baseline_test_dense_grid PROPERTIES LABELS "baseline" TIMEOUT 300)

# ---- wavog_compare: the benchmark program (needs Debian's liboctomap-dev) -----------------------
find_package(octomap QUIET)
if(octomap_FOUND)
  add_executable(wavog_compare src/tools/compare/main.cpp src/tools/compare/options.cpp
    src/tools/compare/workloads.cpp src/tools/compare/measure.cpp src/tools/compare/report.cpp)
  target_include_directories(wavog_compare PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/tools)
  target_link_libraries(wavog_compare PRIVATE wavog_core wavog_io wavog_baseline wavog_tool_support
    ${OCTOMAP_LIBRARIES})
  target_include_directories(wavog_compare SYSTEM PRIVATE ${OCTOMAP_INCLUDE_DIRS})
  target_compile_options(wavog_compare PRIVATE ${WAVOG_WARNINGS})
  target_compile_definitions(wavog_compare PRIVATE WAVOG_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}"
    WAVOG_COMPARE_BUILD_TYPE="${CMAKE_BUILD_TYPE}" WAVOG_OCTOMAP_VERSION="${octomap_VERSION}")
  set_target_properties(wavog_compare PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bin)
  # Smoke run on a tiny workload, so CI builds the program and runs every code path (label
  # "compare"; not a timed test).
  add_test(NAME compare_smoke COMMAND wavog_compare --smoke --out ${CMAKE_BINARY_DIR}/compare_smoke)
  set_tests_properties(compare_smoke PROPERTIES LABELS "compare" TIMEOUT 120)
  # A malformed number is an error naming the option, not a prefix read as the value.
  add_test(NAME compare_bad_number COMMAND wavog_compare --resolutions 0.05x --smoke
    --out ${CMAKE_BINARY_DIR}/compare_bad_number)
  set_tests_properties(compare_bad_number PROPERTIES LABELS "compare" TIMEOUT 60
    PASS_REGULAR_EXPRESSION "--resolutions: not a number: '0.05x'")
  add_test(NAME compare_bad_integer COMMAND wavog_compare --reps 2x --smoke
    --out ${CMAKE_BINARY_DIR}/compare_bad_integer)
  set_tests_properties(compare_bad_integer PROPERTIES LABELS "compare" TIMEOUT 60
    PASS_REGULAR_EXPRESSION "--reps: not a whole number >= 1: '2x'")
else()
  message(STATUS "wavog_compare: OctoMap not found (apt install liboctomap-dev); not built")
endif()
