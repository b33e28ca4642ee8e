# Consumers rostests (issue 41): a bag played into the node, every grid read by amcl's and
# costmap_2d's documented rules and compared with wavog_offline's map of the same bag; the car
# park (simulated by the fixture tools_consumers_bag: its map box grows as the truck drives) and,
# where it is found, the johnny5 bag.
if(CATKIN_ENABLE_TESTING AND TARGET wavog_offline AND TARGET wavog_mapping_node
   AND TARGET wavog_simulate AND EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/test/tools/consumers_demo.test)
  add_executable(test_consumers test/tools/test_consumers.cpp)
  target_link_libraries(test_consumers PRIVATE wavog_ros_config wavog_core ${catkin_LIBRARIES}
                        GTest::GTest)
  target_compile_options(test_consumers PRIVATE ${WAVOG_WARNINGS})
  target_compile_definitions(test_consumers PRIVATE WAVOG_OFFLINE="$<TARGET_FILE:wavog_offline>")
  set_target_properties(test_consumers PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${WAVOG_TOOLS_BIN_DIR})
  add_dependencies(test_consumers ${PROJECT_NAME}_generate_messages_cpp wavog_offline)

  set(_wavog_consumers_bag ${CMAKE_BINARY_DIR}/test_data/consumers_car_park.bag)
  add_test(NAME tools_consumers_bag
           COMMAND sh -c "mkdir -p ${CMAKE_BINARY_DIR}/test_data && $<TARGET_FILE:wavog_simulate> --seed 2 --duration 12 --out ${_wavog_consumers_bag}")
  set_tests_properties(tools_consumers_bag PROPERTIES FIXTURES_SETUP wavog_consumers_bag
                       LABELS "tools" TIMEOUT 120)
  add_rostest(test/tools/consumers_demo.test
              DEPENDENCIES test_consumers wavog_mapping_node wavog_offline)
  set_tests_properties(_ctest_${PROJECT_NAME}_rostest_test_tools_consumers_demo.test PROPERTIES
                       FIXTURES_REQUIRED wavog_consumers_bag LABELS "tools;rostest" TIMEOUT 300
                       ENVIRONMENT "WAVOG_CONSUMERS_BAG=${_wavog_consumers_bag}")
  wavog_real_data_found(_wavog_have_johnny5 rostest_consumers_johnny5.test
                        bags/johnny5_neato_xv11_odom_tf.bag)
  if(_wavog_have_johnny5)
    add_rostest(test/tools/consumers_johnny5.test
                DEPENDENCIES test_consumers wavog_mapping_node wavog_offline)
    set_tests_properties(_ctest_${PROJECT_NAME}_rostest_test_tools_consumers_johnny5.test
                         PROPERTIES LABELS "tools;rostest" TIMEOUT 300
                         ENVIRONMENT "WAVOG_REAL_BAG=${_wavog_data_dir}/bags/johnny5_neato_xv11_odom_tf.bag")
  endif()
endif()
