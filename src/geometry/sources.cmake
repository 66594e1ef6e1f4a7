# The library's side: loads the Gmsh front-end module on first use (gmsh_module.hpp).
list(APPEND QUADVAL_SOURCES
  src/geometry/gmsh_loader.cpp
)
# The module libquadval_gmsh.so, the only code that links libgmsh.
set(QUADVAL_GMSH_MODULE_SOURCES
  src/geometry/gmsh_module.cpp
  src/geometry/gmsh_session.cpp
  src/geometry/read_gmsh_model.cpp
  src/geometry/triangulate.cpp
)
