# Install space: everything a user runs, so that `catkin_make install` (or `cmake --build . --target
# install`) followed by `source <prefix>/setup.bash` gives a working `roslaunch wavog_mapping ...`.
# Included last, after every fragment has defined its targets. One install() per part, with
# catkin's destinations spelled out, so that catkin_lint (make lint) sees what is installed; a
# check at the end fails the configuration when a shared library or a program is neither listed
# here nor a test (what the loop over every target used to guarantee).
# Generated messages, services and the dynamic_reconfigure headers / Python module are installed by
# catkin itself (generate_messages, generate_dynamic_reconfigure_options), package.xml by
# catkin_package. Tested by the ctest entry install_space (test/install/install_test.sh) and, from
# a fresh catkin workspace, by `make install-check`.
if(WAVOG_BUILD_ROS)
  # Programs. The project's shared libraries are found beside the program's directory without a
  # sourced setup file too (relocatable: relative to the program).
  set(_wavog_programs wavog_mapping_node wavog_fleet wavog_site wavog_static_tf wavog_offline wavog_log2bag
                      wavog_simulate wavog_evaluate wavog_paper)
  set_target_properties(${_wavog_programs} PROPERTIES INSTALL_RPATH "$ORIGIN/..")
  install(TARGETS wavog_mapping_node wavog_fleet wavog_site wavog_static_tf wavog_offline wavog_log2bag
                  wavog_simulate wavog_evaluate wavog_paper
          RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
  if(TARGET wavog_compare)  # with OctoMap only
    list(APPEND _wavog_programs wavog_compare)
    set_target_properties(wavog_compare PROPERTIES INSTALL_RPATH "$ORIGIN/..")
    install(TARGETS wavog_compare RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
  endif()
  # The figures of wavog_evaluate, wavog_compare and wavog_paper (matplotlib), beside them.
  catkin_install_python(PROGRAMS scripts/plot_evaluation.py scripts/plot_compare.py
                        scripts/paper_figures.py DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
  install(FILES scripts/figure_common.py DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
  # rviz with the mapper's map frame as its fixed frame (the launch files' rviz:=true).
  install(PROGRAMS scripts/wavog_rviz DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

  # Libraries: the nodelet plugins, what the programs link, and what catkin_package() exports.
  set(_wavog_libraries wavog_core wavog_io wavog_ros_config wavog_ros wavog_mapping_nodelet
                       wavog_fleet_nodelet wavog_baseline)
  set_target_properties(${_wavog_libraries} PROPERTIES INSTALL_RPATH "$ORIGIN")
  install(TARGETS wavog_core wavog_io wavog_ros_config wavog_ros wavog_mapping_nodelet
                  wavog_fleet_nodelet wavog_baseline
          ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
          LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
          RUNTIME DESTINATION ${CATKIN_GLOBAL_BIN_DESTINATION})

  # Headers of the public API: the ROS-free core, the readers / writers (wavog_io) and the ROS
  # layer's headers (wavog_ros_config is exported too).
  install(DIRECTORY include/wavog_mapping/core include/wavog_mapping/io include/wavog_mapping/ros
          DESTINATION ${CATKIN_GLOBAL_INCLUDE_DESTINATION}/wavog_mapping
          FILES_MATCHING PATTERN "*.h")

  # Launch files, configurations, the rviz view, the nodelet plugin description.
  install(DIRECTORY launch config rviz DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})
  install(FILES nodelet_plugins.xml DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})
else()
  #catkin_lint: skip (a build without ROS is not a catkin package: no catkin destinations)
  # Without ROS: the core and its readers / writers, their headers, the baseline and wavog_compare.
  include(GNUInstallDirs)
  set(_wavog_programs "")
  set(_wavog_libraries wavog_core wavog_io wavog_baseline)
  if(TARGET wavog_compare)
    set(_wavog_programs wavog_compare)
    set_target_properties(wavog_compare PROPERTIES INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}")
    install(TARGETS wavog_compare RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  endif()
  set_target_properties(${_wavog_libraries} PROPERTIES INSTALL_RPATH "$ORIGIN")
  install(TARGETS ${_wavog_libraries} ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  install(DIRECTORY include/wavog_mapping/core include/wavog_mapping/io
          DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/wavog_mapping FILES_MATCHING PATTERN "*.h")
endif()

# Every shared library and every program of the build is installed above, or is a test, a
# benchmark, a fuzz harness or the rviz check's scene (test/ros/room_scene.cpp). This check
# replaces catkin_lint's, which knows tests by name only (bench_core, room_scene):
#catkin_lint: ignore UNINSTALLED_TARGET
get_property(_wavog_targets DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR} PROPERTY BUILDSYSTEM_TARGETS)
foreach(_t ${_wavog_targets})
  get_target_property(_type ${_t} TYPE)
  if(_type MATCHES "^(SHARED_LIBRARY|MODULE_LIBRARY)$" AND NOT _t IN_LIST _wavog_libraries)
    message(FATAL_ERROR "cmake/install.cmake: shared library ${_t} is not installed: add it there")
  endif()
  if(_type STREQUAL "EXECUTABLE" AND NOT _t IN_LIST _wavog_programs
     AND NOT _t MATCHES "^(test_|bench_|fuzz_)" AND NOT _t STREQUAL "room_scene")
    message(FATAL_ERROR "cmake/install.cmake: program ${_t} is not installed: add it there "
                        "(or name it test_* / bench_* if it is one)")
  endif()
endforeach()

# ---- Test: `cmake --install` of this build tree into a temporary prefix, then the launch files
# from that prefix alone (ctest label "install"; `make install-check` does the same from a fresh
# catkin workspace with `catkin_make install`).
if(WAVOG_BUILD_ROS AND CATKIN_ENABLE_TESTING AND TARGET wavog_mapping_node AND TARGET wavog_simulate)
  add_test(NAME install_space
           COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test/install/install_test.sh
                   --build ${CMAKE_BINARY_DIR})
  set_tests_properties(install_space PROPERTIES LABELS "install" TIMEOUT 300)
endif()
