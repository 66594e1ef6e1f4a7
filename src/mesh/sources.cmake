list(APPEND QUADVAL_SOURCES
  src/mesh/element_type.cpp
  src/mesh/error.cpp
  src/mesh/mesh.cpp
)
