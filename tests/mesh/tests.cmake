list(APPEND QUADVAL_TEST_SOURCES
  mesh/element_type_test.cpp
)
