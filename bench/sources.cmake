list(APPEND QUADVAL_BENCH_SOURCES
  recombine_bench.cpp
  io_bench.cpp
  pyramid_bench.cpp
  jacobian_bench.cpp
  mu_bench.cpp
  lookahead_bench.cpp
)
