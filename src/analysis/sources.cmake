list(APPEND QUADVAL_SOURCES
  src/analysis/jacobian_space.cpp
  src/analysis/jacobian_product.cpp
  src/analysis/pyramid_space.cpp
  src/analysis/jacobian_samples.cpp
  src/analysis/jacobian_engine.cpp
  src/analysis/jacobian_bounds.cpp
  src/analysis/linear_jacobian.cpp
  src/analysis/scaled_jacobian_space.cpp
  src/analysis/scaled_jacobian.cpp
  src/analysis/mu_space.cpp
  src/analysis/mu_metric.cpp
  src/analysis/mu_constant.cpp
  src/analysis/mu_bounds.cpp
  src/analysis/check_mesh.cpp
  src/analysis/check_report.cpp
)
