list(APPEND QUADVAL_SOURCES
  src/recombine/quad_quality.cpp
  src/recombine/triangle_input.cpp
  src/recombine/feature_edges.cpp
  src/recombine/node_order.cpp
  src/recombine/dual_graph.cpp
  src/recombine/blossom_solver.cpp
  src/recombine/matching.cpp
  src/recombine/mixed_mesh.cpp
  src/recombine/repair.cpp
  src/recombine/smoothing.cpp
  src/recombine/surface_projection.cpp
  src/recombine/boundary_slide.cpp
  src/recombine/quad_cleanup.cpp
  src/recombine/refine.cpp
  src/recombine/recombine_stats.cpp
  src/recombine/recombine.cpp
  src/recombine/lookahead_state.cpp
  src/recombine/lookahead_tree.cpp
  src/recombine/lookahead_matching.cpp
  src/recombine/leftover_paths.cpp
  src/recombine/lookahead_parity.cpp
)
list(APPEND QUADVAL_SOURCES src/recombine/lemon_matching.cpp)
# LEMON 1.3 calls std::allocator::construct/destroy, removed in C++20: this one file is C++17.
set_source_files_properties(src/recombine/lemon_matching.cpp PROPERTIES COMPILE_OPTIONS "-std=c++17")
