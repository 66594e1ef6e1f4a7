// Test main: in debug builds, trap the floating-point exceptions that signal a bug
// (STYLE.md §11), so that a NaN stops the run where it was made.
#include <gtest/gtest.h>
#ifndef NDEBUG
#include <cfenv>
#endif

int main(int argc, char** argv) {
#ifndef NDEBUG
  feenableexcept(FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW);
#endif
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
