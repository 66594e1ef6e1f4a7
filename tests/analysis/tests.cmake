list(APPEND QUADVAL_TEST_SOURCES
  analysis/jacobian_bounds_test.cpp
  analysis/jacobian_exact_test.cpp
)
