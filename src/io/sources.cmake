list(APPEND QUADVAL_SOURCES
  src/io/atomic_file.cpp
)
