list(APPEND QUADVAL_TEST_SOURCES
  cli/info_cli_test.cpp
)
