list(APPEND QUADVAL_SOURCES
  src/bezier/bernstein_simplex.cpp
  src/bezier/bezier_basis.cpp
  src/bezier/bernstein_bisection.cpp
  src/bezier/bernstein_product.cpp
  src/bezier/pyramid_basis.cpp
)
