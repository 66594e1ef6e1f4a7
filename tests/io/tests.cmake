list(APPEND QUADVAL_TEST_SOURCES
  io/convert_cli_test.cpp
  io/file_bytes_test.cpp
  io/msh_gmsh_test.cpp
  io/msh_read_test.cpp
  io/msh_round_trip_test.cpp
  io/obj_runs_test.cpp
  io/out_buffer_test.cpp
  io/parallel_lines_test.cpp
  io/parallel_lines22_test.cpp
  io/surface_read_test.cpp
  io/surface_write_test.cpp
  io/vtu_write_test.cpp
  io/svg_test.cpp
)
