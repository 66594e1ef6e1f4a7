list(APPEND QUADVAL_TEST_SOURCES
  analysis/mu_bounds_test.cpp
  analysis/mu_sampling_test.cpp
  analysis/mu_filter_test.cpp
  analysis/mu_bernstein_product_test.cpp
  analysis/mu_constant_test.cpp
  analysis/jacobian_bounds_test.cpp
  analysis/jacobian_exact_test.cpp
  analysis/gmsh_agreement_test.cpp
  analysis/check_cli_test.cpp
  analysis/scaled_jacobian_test.cpp
  analysis/quality_cli_test.cpp
  analysis/pyramid_jacobian_test.cpp
  analysis/linear_fast_path_test.cpp
  analysis/jacobian_batch_test.cpp
  analysis/check_threads_test.cpp
)
