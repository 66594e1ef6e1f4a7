list(APPEND QUADVAL_TEST_SOURCES
  cli/info_cli_test.cpp
  cli/main_cli_test.cpp
)
