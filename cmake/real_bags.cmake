# Rostests of the third-party bags in ../shared/data/bags (issue 27): each played through
# launch/playback.launch as that directory's README says; registered only where its bag is found
# (cmake/real_data.cmake). The bag's path reaches the launch file through the environment (rostest
# ARGS would end up in the test's name), as for test/tools/real_bag.test.
if(CATKIN_ENABLE_TESTING AND TARGET wavog_mapping_node AND TARGET wavog_static_tf)
  # wavog_real_bag_rostest(<name> <bag below the data directory>): test/tools/real_bag_<name>.test
  # on that bag, where it is found; the one test program is built with the first.
  function(wavog_real_bag_rostest name file)
    wavog_real_data_found(_have tools_rostest_real_bag_${name} ${file})
    if(NOT _have)
      return()
    endif()
    if(NOT TARGET test_real_bags)
      add_executable(test_real_bags test/tools/test_real_bags.cpp)
      target_link_libraries(test_real_bags PRIVATE wavog_ros_includes ${catkin_LIBRARIES}
                            GTest::GTest)
      target_compile_options(test_real_bags PRIVATE ${WAVOG_WARNINGS})
      set_target_properties(test_real_bags PROPERTIES RUNTIME_OUTPUT_DIRECTORY
                            ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
      add_dependencies(test_real_bags ${PROJECT_NAME}_generate_messages_cpp)
    endif()
    add_rostest(test/tools/real_bag_${name}.test
                DEPENDENCIES test_real_bags wavog_mapping_node wavog_static_tf)
    set_tests_properties(_ctest_${PROJECT_NAME}_rostest_test_tools_real_bag_${name}.test PROPERTIES
                         LABELS "tools;rostest" TIMEOUT 240
                         ENVIRONMENT "WAVOG_REAL_BAG=${WAVOG_DATA_DIR}/${file}")
  endfunction()
  wavog_real_bag_rostest(johnny5 bags/johnny5_neato_xv11_odom_tf.bag)
  wavog_real_bag_rostest(datmo bags/datmo_rplidar_mocap_overtakes.bag)
  wavog_real_bag_rostest(oko bags/oko_custom_lidar_odom_only.bag)
endif()
