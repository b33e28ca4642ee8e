# Install space: everything a user runs, so that `catkin_make install` (or `cmake --build . --target
# install`) followed by `source <prefix>/setup.bash` gives a working `roslaunch wavog_mapping ...`.
# Included last, after every fragment has defined its targets; targets that a build leaves out
# (wavog_compare without OctoMap, the ROS part with -DWAVOG_BUILD_ROS=OFF) are skipped.
# Generated messages, services and the dynamic_reconfigure headers / Python module are installed by
# catkin itself (generate_messages, generate_dynamic_reconfigure_options), package.xml by
# catkin_package. Tested by the ctest entry install_space (test/install/install_test.sh) and, from
# a fresh catkin workspace, by `make install-check`.
if(WAVOG_BUILD_ROS)
  set(_wavog_bin ${CATKIN_PACKAGE_BIN_DESTINATION})
  set(_wavog_lib ${CATKIN_PACKAGE_LIB_DESTINATION})
  set(_wavog_include ${CATKIN_GLOBAL_INCLUDE_DESTINATION})
  set(_wavog_share ${CATKIN_PACKAGE_SHARE_DESTINATION})
else()
  include(GNUInstallDirs)
  set(_wavog_bin ${CMAKE_INSTALL_BINDIR})
  set(_wavog_lib ${CMAKE_INSTALL_LIBDIR})
  set(_wavog_include ${CMAKE_INSTALL_INCLUDEDIR})
  set(_wavog_share ${CMAKE_INSTALL_DATAROOTDIR}/wavog_mapping)
endif()

# Programs: the node, the tools, the static-tf helper.
foreach(_t wavog_mapping_node wavog_fleet wavog_static_tf wavog_offline wavog_log2bag wavog_simulate
           wavog_evaluate wavog_compare wavog_paper)
  if(TARGET ${_t})
    # The project's shared libraries are found beside the program's directory without a sourced
    # setup file too (relocatable: relative to the program).
    set_target_properties(${_t} PROPERTIES INSTALL_RPATH "$ORIGIN/..")
    install(TARGETS ${_t} RUNTIME DESTINATION ${_wavog_bin})
  endif()
endforeach()

# Libraries: every shared library of the project (the nodelet plugin and what the programs link),
# and the libraries catkin_package() exports (whatever their type), so that find_package of the
# installed package finds them.
get_property(_wavog_targets DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR} PROPERTY BUILDSYSTEM_TARGETS)
set(_wavog_install_libs ${PROJECT_LIBRARIES})
foreach(_t ${_wavog_targets})
  get_target_property(_type ${_t} TYPE)
  if(_type STREQUAL "SHARED_LIBRARY" OR _type STREQUAL "MODULE_LIBRARY")
    list(APPEND _wavog_install_libs ${_t})
  endif()
endforeach()
list(REMOVE_DUPLICATES _wavog_install_libs)
foreach(_t ${_wavog_install_libs})
  if(TARGET ${_t})
    set_target_properties(${_t} PROPERTIES INSTALL_RPATH "$ORIGIN")
    install(TARGETS ${_t}
            ARCHIVE DESTINATION ${_wavog_lib}
            LIBRARY DESTINATION ${_wavog_lib}
            RUNTIME DESTINATION ${_wavog_bin})
  endif()
endforeach()

# Headers of the public API: the ROS-free core, the readers / writers (wavog_io) and the ROS
# layer's headers (wavog_ros_config is exported too).
foreach(_dir core io ros)
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/include/wavog_mapping/${_dir})
    install(DIRECTORY include/wavog_mapping/${_dir}
            DESTINATION ${_wavog_include}/wavog_mapping FILES_MATCHING PATTERN "*.h")
  endif()
endforeach()

# Launch files, configurations, the rviz view, the nodelet plugin description.
install(DIRECTORY launch config rviz DESTINATION ${_wavog_share})
install(FILES nodelet_plugins.xml DESTINATION ${_wavog_share})

# ---- Test: `cmake --install` of this build tree into a temporary prefix, then the launch files
# from that prefix alone (ctest label "install"; `make install-check` does the same from a fresh
# catkin workspace with `catkin_make install`).
if(WAVOG_BUILD_ROS AND CATKIN_ENABLE_TESTING AND TARGET wavog_mapping_node AND TARGET wavog_simulate)
  add_test(NAME install_space
           COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test/install/install_test.sh
                   --build ${CMAKE_BINARY_DIR})
  set_tests_properties(install_space PROPERTIES LABELS "install" TIMEOUT 300)
endif()
