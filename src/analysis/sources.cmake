# Link order is code layout: the validity check's path (spaces, products, engine, first-order
# and straight-sided paths, the check loop and its summary) comes first, so that its first
# run touches fewer 64 KiB blocks of code (each a page fault, about 1.5 us here: on
# quad_h0.4_o2 they were a seventh of the check); the quality measures and the rest follow.
list(APPEND QUADVAL_SOURCES
  src/analysis/jacobian_space.cpp
  src/analysis/jacobian_product.cpp
  src/analysis/jacobian_engine.cpp
  src/analysis/jacobian_bounds.cpp
  src/analysis/midpoint_probe.cpp
  src/analysis/linear_jacobian.cpp
  src/analysis/straight_sided.cpp
  src/analysis/check_mesh.cpp
  src/analysis/worker_threads.cpp
  src/analysis/check_summary.cpp
  src/analysis/jacobian_samples.cpp
  src/analysis/pyramid_space.cpp
  src/analysis/ratio_refinement.cpp
  src/analysis/scaled_jacobian_space.cpp
  src/analysis/scaled_jacobian_quotient.cpp
  src/analysis/scaled_jacobian_probe.cpp
  src/analysis/bilinear_quad_quality.cpp
  src/analysis/trilinear_hex_sj.cpp
  src/analysis/linear_pyramid_sj.cpp
  src/analysis/scaled_jacobian.cpp
  src/analysis/mu_space.cpp
  src/analysis/mu_metric.cpp
  src/analysis/mu_constant.cpp
  src/analysis/straight_simplex_mu.cpp
  src/analysis/vertex_metric_ratio.cpp
  src/analysis/trilinear_hex_mu.cpp
  src/analysis/linear_pyramid_mu.cpp
  src/analysis/linear_prism_mu.cpp
  src/analysis/mu_control_bound.cpp
  src/analysis/mu_bounds.cpp
  src/analysis/check_report.cpp
)
