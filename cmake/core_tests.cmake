# Core unit tests: plain gtest executables registered with ctest, label "core". They need no ROS,
# so they also run under the sanitizers (make test-asan).
find_package(GTest REQUIRED)

add_library(wavog_test_support STATIC test/core/dense_reference.cpp test/core/test_support.cpp)
target_link_libraries(wavog_test_support PUBLIC wavog_core wavog_io GTest::GTest Threads::Threads
  ZLIB::ZLIB)
# The tests of the core's private parts include them as ../../src/core/<part>/<file>.
target_include_directories(wavog_test_support PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/test/core
  ${CMAKE_CURRENT_SOURCE_DIR}/src/core)
target_compile_options(wavog_test_support PRIVATE ${WAVOG_WARNINGS})
target_compile_definitions(wavog_test_support PUBLIC
  WAVOG_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")

# `core_tests` builds every core test (make test-asan builds only these).
add_custom_target(core_tests)
# wavog_core_test(<name> [REAL_DATA <file>...]): with REAL_DATA, the tests named RealData* (gtest
# filter *.RealData*) read those files of the data directory and run as a second ctest entry,
# core_<name>_real_data, registered only where the files are found (cmake/real_data.cmake).
function(wavog_core_test name)
  cmake_parse_arguments(ARG "" "" "REAL_DATA" ${ARGN})
  add_executable(${name} test/core/${name}.cpp)
  add_dependencies(core_tests ${name})
  target_link_libraries(${name} PRIVATE wavog_test_support GTest::Main)
  target_compile_options(${name} PRIVATE ${WAVOG_WARNINGS})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  wavog_add_gtest(core_${name} ${name} ${CMAKE_BINARY_DIR}/test_results/core core 900
                  "${ARG_REAL_DATA}")
endfunction()

wavog_core_test(test_haar)
wavog_core_test(test_params)
wavog_core_test(test_reference_equivalence REAL_DATA fr079-corrected.log.gz)
wavog_core_test(test_lazy_forgetting)
wavog_core_test(test_forget_half_life)
wavog_core_test(test_reflection REAL_DATA fr079-corrected.log.gz)
wavog_core_test(test_cell_runs)
wavog_core_test(test_ndt REAL_DATA fr079-corrected.log.gz)
wavog_core_test(test_readout)
wavog_core_test(test_map_io)
wavog_core_test(test_save_crash_safety)
wavog_core_test(test_carmen_reader REAL_DATA fr079-corrected.log.gz csail-robotlaser1.log.gz)
wavog_core_test(test_motion_compensation)
wavog_core_test(test_scan_classifier)
wavog_core_test(test_integrate_stats)
wavog_core_test(test_defaults)
wavog_core_test(test_parallel_integration REAL_DATA fr079-corrected.log.gz)
wavog_core_test(test_limits)
wavog_core_test(test_repeated_scan)
wavog_core_test(test_region_shards)
wavog_core_test(test_tiles)
