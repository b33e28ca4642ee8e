# Tests on real data (the logs and bags of ../shared/data, recorded by others, never copied into
# the repository). They are registered only where the data is found: $WAVOG_DATA_DIR, else
# ../shared/data beside the repository. A clone with nothing beside it still passes `make test`;
# the tests left out are listed in <build>/real_data_missing.txt, which scripts/run_tests.sh
# prints at the end. With WAVOG_REQUIRE_DATA=1 in the environment (CI), a missing file fails the
# configuration instead.
if(DEFINED ENV{WAVOG_DATA_DIR})
  # catkin_lint: the data lie outside the repository by design; CI and users point here at them.
  #catkin_lint: ignore_once ENV_VAR
  file(TO_CMAKE_PATH "$ENV{WAVOG_DATA_DIR}" WAVOG_DATA_DIR)
else()
  get_filename_component(WAVOG_DATA_DIR ${CMAKE_CURRENT_SOURCE_DIR}/../shared/data ABSOLUTE)
endif()
set(WAVOG_REAL_DATA_MISSING_FILE ${CMAKE_BINARY_DIR}/real_data_missing.txt)
file(WRITE ${WAVOG_REAL_DATA_MISSING_FILE} "")

# wavog_real_data_found(<out_var> <test name> <file>...): sets <out_var> TRUE when every file
# (relative to the data directory) exists; otherwise FALSE, and the test is listed as not run (or,
# with WAVOG_REQUIRE_DATA=1, the configuration fails naming the file).
function(wavog_real_data_found out_var test_name)
  set(_missing "")
  foreach(_f ${ARGN})
    if(NOT EXISTS ${WAVOG_DATA_DIR}/${_f})
      list(APPEND _missing ${_f})
    endif()
  endforeach()
  if(_missing STREQUAL "")
    set(${out_var} TRUE PARENT_SCOPE)
    return()
  endif()
  if("$ENV{WAVOG_REQUIRE_DATA}" STREQUAL "1")
    message(FATAL_ERROR "WAVOG_REQUIRE_DATA=1 but ${test_name} needs ${_missing}, not found in "
                        "${WAVOG_DATA_DIR} (set WAVOG_DATA_DIR)")
  endif()
  string(REPLACE ";" ", " _list "${_missing}")
  file(APPEND ${WAVOG_REAL_DATA_MISSING_FILE} "${test_name} (needs ${_list})\n")
  set(${out_var} FALSE PARENT_SCOPE)
endfunction()

# wavog_add_gtest(<test> <executable> <xml dir> <label> <timeout> "<real data files>"): registers a
# gtest executable. With real data files, its RealData* tests are a second entry <test>_real_data,
# registered where the files are found; the first entry runs every other test. A filter that
# selects no test fails (a renamed test must not silently drop out).
function(wavog_add_gtest test exe xml_dir label timeout real_data)
  if(real_data STREQUAL "")
    add_test(NAME ${test} COMMAND ${exe} --gtest_output=xml:${xml_dir}/${exe}.xml
             WORKING_DIRECTORY ${CMAKE_BINARY_DIR})
    set_tests_properties(${test} PROPERTIES LABELS "${label}" TIMEOUT ${timeout})
    return()
  endif()
  add_test(NAME ${test} COMMAND ${exe} --gtest_filter=-*.RealData*
           --gtest_output=xml:${xml_dir}/${exe}.xml WORKING_DIRECTORY ${CMAKE_BINARY_DIR})
  set_tests_properties(${test} PROPERTIES LABELS "${label}" TIMEOUT ${timeout}
                       FAIL_REGULAR_EXPRESSION "Running 0 tests from")
  wavog_real_data_found(_found ${test}_real_data ${real_data})
  if(_found)
    add_test(NAME ${test}_real_data COMMAND ${exe} --gtest_filter=*.RealData*
             --gtest_output=xml:${xml_dir}/${exe}_real_data.xml WORKING_DIRECTORY ${CMAKE_BINARY_DIR})
    set_tests_properties(${test}_real_data PROPERTIES LABELS "${label};real_data"
                         TIMEOUT ${timeout} FAIL_REGULAR_EXPRESSION "Running 0 tests from"
                         ENVIRONMENT "WAVOG_DATA_DIR=${WAVOG_DATA_DIR}")
  endif()
endfunction()
