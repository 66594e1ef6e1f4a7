#pragma once
/// Shape quality of linear quadrangles, as pure free functions (STYLE.md §3).
///
/// Corners are given in order around the quad (Gmsh order for type 3). Angles are measured in
/// 3D and signed with a reference normal, so that the functions serve planar meshes and
/// surfaces alike: a corner whose turn disagrees with the normal is reflex (angle > pi) or
/// inverted, and makes the quad invalid.

#include <array>
#include <vector>

#include "quadval/mesh.hpp"

namespace quadval {

using QuadCorners = std::array<std::array<double, 3>, 4>;

enum class QuadShape {
  ok,          ///< every edge and the normal have non-zero length: the value is meaningful
  degenerate,  ///< a zero-length edge or a zero reference normal: no angle exists
};

struct QuadEta {
  double eta;       ///< in [0, 1]; 0 when degenerate
  QuadShape shape;
};

/// Angle quality eta of Paper I eq. (3) (Borouchaki & Frey):
///   eta = max(1 - (2/pi) max_k |pi/2 - alpha_k|, 0)
/// with alpha_k the interior angle at corner k, taken in (pi, 2 pi) when the corner turns
/// against `normal` (so a non-convex or inverted quad scores 0).
/// Ideal 1 (rectangle); full range [0, 1]; 0 for a non-convex, inverted or flat corner.
/// Acceptable: above about 0.4 (Gmsh's Blossom gives eta_min ~ 0.4 on Paper I §8.1).
/// @param normal  any vector on the side the quad should face; its length does not matter.
/// A zero-length edge or a zero `normal` gives {0, degenerate}.
QuadEta quad_eta(const QuadCorners& x, const std::array<double, 3>& normal) noexcept;

/// quad_eta with the quad's own normal (x2 - x0) × (x3 - x1) (the cross product of the
/// diagonals): the orientation-free quality of the shape. An inverted quad has no meaning
/// here; a self-intersecting ("bow-tie") quad has a zero or flipped diagonal normal and
/// scores 0 or degenerate.
QuadEta quad_eta(const QuadCorners& x) noexcept;

/// Smallest signed corner sine: min_k ((e_k+ × e_k-) · n̂) / (|e_k+| |e_k-|), with e_k+ and e_k-
/// the edges leaving corner k forward and backward. This is the scaled Jacobian determinant
/// of the bilinear map at the corners; a planar bilinear quad is valid (det J > 0 everywhere)
/// iff all four are > 0. Ideal 1 (rectangle); full range [-1, 1]; <= 0 invalid.
/// Knupp (2000) "scaled Jacobian" of a quadrilateral. Degenerate input gives -1.
double quad_min_corner_sine(const QuadCorners& x, const std::array<double, 3>& normal) noexcept;

/// quad_eta (own normal) of every element of the mesh in block order, `other` for the
/// elements that are not quadrangles; on OpenMP's threads (the values do not depend on them).
std::vector<double> element_eta(const Mesh& mesh, double other);

}  // namespace quadval
