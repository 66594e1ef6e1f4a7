list(APPEND QUADVAL_SOURCES
  src/mesh/element_type.cpp
  src/mesh/reference_nodes.cpp
  src/mesh/error.cpp
  src/mesh/mesh.cpp
  src/mesh/topology.cpp
  src/mesh/size_field.cpp
  src/mesh/planar_domain.cpp
  src/mesh/polynomial_space.cpp
  src/mesh/lagrange_basis.cpp
)
