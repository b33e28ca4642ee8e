# `make build` (the `all` target) builds what a user runs; the tests, benchmarks and the data they
# make hang off the `tests` target instead (catkin's gtests and rostests already do), which
# `make test` builds (scripts/build.sh without targets: all, then tests). Issue 41: building every
# test took 20 minutes on 2 cores for a user who only wanted to run the node. Included after every
# fragment that defines targets. Also the repository's own checks as ctest entries.
if(NOT TARGET tests)
  add_custom_target(tests)
endif()
get_property(_wavog_targets DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR} PROPERTY BUILDSYSTEM_TARGETS)
foreach(_t ${_wavog_targets})
  if(_t MATCHES "^(test_|bench_)" OR _t MATCHES "^(room_scene|wavog_test_support)$")
    set_target_properties(${_t} PROPERTIES EXCLUDE_FROM_ALL TRUE)
    add_dependencies(tests ${_t})
  endif()
endforeach()

if(CATKIN_ENABLE_TESTING OR BUILD_TESTING)
  # No test, benchmark or test support in `all` (the Makefile generator's list of it).
  add_test(NAME build_all_holds_no_tests
           COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test/tools/check_all_target.sh
                   ${CMAKE_BINARY_DIR})
  # Every relative link of README.md and docs/*.md names a file.
  add_test(NAME docs_links
           COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/scripts/check_doc_links.py
                   ${CMAKE_CURRENT_SOURCE_DIR})
  set_tests_properties(build_all_holds_no_tests docs_links PROPERTIES LABELS "tools")
endif()
