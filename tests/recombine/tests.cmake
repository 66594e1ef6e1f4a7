list(APPEND QUADVAL_TEST_SOURCES
  recombine/quad_quality_test.cpp
  recombine/blossom_optimality_test.cpp
  recombine/blossom_solver_test.cpp
  recombine/boundary_slide_test.cpp
  recombine/smoothing_test.cpp
  recombine/quad_cleanup_test.cpp
  recombine/node_order_test.cpp
  recombine/triangle_input_test.cpp
  recombine/recombine_test.cpp
  recombine/repair_test.cpp
  recombine/recombine_input_test.cpp
  recombine/recombine_cli_test.cpp
  recombine/lookahead_criterion_test.cpp
  recombine/lookahead_tree_test.cpp
  recombine/lookahead_parity_test.cpp
  recombine/lookahead_cli_test.cpp
)
