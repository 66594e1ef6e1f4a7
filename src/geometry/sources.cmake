list(APPEND QUADVAL_SOURCES
  src/geometry/gmsh_session.cpp
  src/geometry/read_gmsh_model.cpp
  src/geometry/triangulate.cpp
)
