# Built only when QUADVAL_WITH_GMSH (see tests/CMakeLists.txt).
list(APPEND QUADVAL_TEST_SOURCES
  geometry/triangulate_test.cpp
  geometry/mesh_cli_test.cpp
  geometry/gmsh_module_test.cpp
)
