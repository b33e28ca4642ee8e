# Core benchmarks (Google Benchmark from Debian's libbenchmark-dev): `make bench`, not in make test.
find_package(benchmark QUIET)
if(benchmark_FOUND)
  add_executable(bench_core test/benchmark/bench_core.cpp)
  target_link_libraries(bench_core PRIVATE wavog_core wavog_io benchmark::benchmark)
  target_compile_options(bench_core PRIVATE ${WAVOG_WARNINGS})
  target_compile_definitions(bench_core PRIVATE WAVOG_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
  set_target_properties(bench_core PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bench)
  # What dense leaf tiles could save in bytes (issue 29), by hand: ./build/bench/bench_tiles.
  add_executable(bench_tiles test/benchmark/bench_tiles.cpp)
  target_link_libraries(bench_tiles PRIVATE wavog_core wavog_io)
  target_compile_options(bench_tiles PRIVATE ${WAVOG_WARNINGS})
  target_compile_definitions(bench_tiles PRIVATE WAVOG_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
  set_target_properties(bench_tiles PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bench)
  # Smoke run in make test: builds and runs one short case so the benchmark cannot rot.
  add_test(NAME bench_core_smoke COMMAND bench_core --benchmark_filter=synthetic80m/10cm/clamp
           --benchmark_repetitions=1)
  set_tests_properties(bench_core_smoke PROPERTIES LABELS "bench" TIMEOUT 300
                       ENVIRONMENT WAVOG_BENCH_SCANS=50)
endif()
