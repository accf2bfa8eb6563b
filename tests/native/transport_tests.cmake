# Test binaries of the light-transport building blocks, one per part, registered like the others:
#   add_executable(camera_test camera_test.cpp)
#   target_link_libraries(camera_test PRIVATE toyrt_test_support GTest::gtest_main)
#   gtest_discover_tests(camera_test DISCOVERY_TIMEOUT 60)
