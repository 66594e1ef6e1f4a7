#pragma once
// How an element family's reference domain splits into simplex factors (the tensor
// structure of bezier_basis.hpp), in Gmsh's reference coordinates. Internal to
// src/analysis.
#include <vector>

#include "quadval/element_type.hpp"

namespace quadval {

/// One factor of the element's reference domain.
struct FactorShape {
  int dim;        ///< 1, 2, 3
  int first;      ///< first Gmsh coordinate it covers
  bool interval;  ///< a [-1, 1] Gmsh direction mapped to [0, 1] (line factors)
};

/// The factors of a family: line [line], triangle [triangle], quadrangle [line, line],
/// tetrahedron [tetrahedron], prism [triangle, line], hexahedron [line, line, line]; empty
/// for other families.
inline std::vector<FactorShape> factor_shapes(ElementFamily f) {
  switch (f) {
    case ElementFamily::line: return {{1, 0, true}};
    case ElementFamily::triangle: return {{2, 0, false}};
    case ElementFamily::quadrangle: return {{1, 0, true}, {1, 1, true}};
    case ElementFamily::tetrahedron: return {{3, 0, false}};
    case ElementFamily::prism: return {{2, 0, false}, {1, 2, true}};
    case ElementFamily::hexahedron: return {{1, 0, true}, {1, 1, true}, {1, 2, true}};
    default: return {};
  }
}

}  // namespace quadval
