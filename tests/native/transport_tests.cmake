# Test binaries of the light-transport building blocks, one per part, registered like the others.
foreach(name camera_test sampling_test lights_test materials_test)
  add_executable(${name} ${name}.cpp)
  target_link_libraries(${name} PRIVATE toyrt_test_support GTest::gtest_main)
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60)
endforeach()
