# Regression tests for what the fuzzer found (tests/fuzz, docs/robustness.md).
add_executable(robustness_test robustness_test.cpp)
target_link_libraries(robustness_test PRIVATE toyrt_test_support GTest::gtest_main)
gtest_discover_tests(robustness_test DISCOVERY_TIMEOUT 60)
