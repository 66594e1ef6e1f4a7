list(APPEND QUADVAL_TEST_SOURCES
  mesh/element_type_test.cpp
  mesh/topology_test.cpp
  mesh/size_field_test.cpp
  mesh/planar_domain_test.cpp
  mesh/reference_nodes_test.cpp
  mesh/lagrange_basis_test.cpp
)
