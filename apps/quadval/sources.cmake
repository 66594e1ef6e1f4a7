set(QUADVAL_CLI_SOURCES
  apps/quadval/main.cpp
  apps/quadval/info.cpp
  apps/quadval/convert.cpp
)
