list(APPEND QUADVAL_TEST_SOURCES
  bezier/bezier_basis_test.cpp
  bezier/bernstein_bisection_test.cpp
  bezier/rational_rounding_test.cpp
)
