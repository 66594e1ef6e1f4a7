list(APPEND QUADVAL_SOURCES
  src/io/atomic_file.cpp
  src/io/file_bytes.cpp
  src/io/mesh_io.cpp
  src/io/msh_read.cpp
  src/io/msh_read_ascii.cpp
  src/io/msh_read_binary.cpp
  src/io/msh_write.cpp
  src/io/parallel_lines.cpp
  src/io/surface_read.cpp
  src/io/surface_write.cpp
  src/io/vtk_node_order.cpp
  src/io/vtu_write.cpp
  src/io/svg_common.cpp
  src/io/svg_histogram.cpp
  src/io/svg_mesh.cpp
)
