list(APPEND QUADVAL_TEST_SOURCES
  io/convert_cli_test.cpp
  io/msh_read_test.cpp
  io/msh_round_trip_test.cpp
)
