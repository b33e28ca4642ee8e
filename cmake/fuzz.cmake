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
endif()
