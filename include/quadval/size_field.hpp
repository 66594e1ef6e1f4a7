#pragma once
/// A mesh size field h(x, y, z): the characteristic edge length a mesh should have near a
/// point (Paper I §2, thesis lines 470-480), given by the user as an expression such as
/// "0.1 + 0.08*sin(3*x)*cos(6*y)".
///
/// Expressions are parsed by muparser: variables x, y, z; constants pi and e (also _pi, _e);
/// operators + - * / ^, comparisons and ?:, functions sin cos tan asin acos atan sinh cosh
/// tanh exp ln log log2 log10 sqrt abs sign rint, variadic min max sum avg.

#include <array>
#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace quadval {

struct Mesh;

class SizeField {
 public:
  /// Parses `expression`. Throws InputError ("size expression '...': byte offset N: ...")
  /// when it does not parse, uses a variable other than x, y, z, or is empty.
  static SizeField from_expression(std::string expression);

  /// The constant field h = value. @pre value > 0 and finite.
  static SizeField constant(double value);

  /// h at (x, y, z). Thread-safe: each thread evaluates with its own parser (muparser
  /// objects keep their stack and variables inside, so one cannot be shared). No check of
  /// the sign here: see check_positive_*.
  double operator()(double x, double y, double z) const;

  /// The expression as given (for a constant field, its decimal value).
  const std::string& expression() const noexcept;

  /// Throws InputError naming the first node (index, coordinates) where h is not a finite
  /// positive number. @param coords #nodes × 3. @param what names the nodes in the message,
  /// e.g. "mesh node" or "geometry point".
  void check_positive_at(std::span<const double> coords, const std::string& what) const;

  /// Samples h on a regular (n+1)^3 grid over the box (minX minY minZ maxX maxY maxZ; a flat
  /// direction gets one sample) and throws InputError naming the first sample where h is
  /// not a finite positive number. Sampling cannot prove positivity everywhere; it catches
  /// the expressions that are wrong at a glance before a mesher runs with them.
  void check_positive_on_box(const std::array<double, 6>& box, int n = 16) const;

  struct Impl;

 private:
  explicit SizeField(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}
  std::shared_ptr<const Impl> impl_;  // immutable, shared by copies
};

/// Adimensional length of the segment a→b in the size field h (Paper I eq. 1):
/// l^h = |b - a| ∫_0^1 dt / h(a + t (b - a)), by adaptive Simpson quadrature to a relative
/// tolerance of about 1e-8. Returns +inf if h is not positive somewhere it is evaluated.
double normalized_edge_length(const SizeField& h, const std::array<double, 3>& a,
                              const std::array<double, 3>& b);

/// l^h (eq. 1) of every unique edge of the 2D elements of `mesh` (the corner cycle of each
/// triangle and quadrangle; higher-order nodes ignored), ordered by (smaller, larger) corner
/// node index.
std::vector<double> mesh_normalized_edge_lengths(const Mesh& mesh, const SizeField& h);

/// Efficiency index tau in percent (Paper I eq. 2): 100 exp(mean d_i) with d_i = l_i - 1 if
/// l_i < 1 and 1/l_i - 1 otherwise. 100 for a unit mesh; an infinite l counts as d = -1.
/// @pre lengths is not empty.
double efficiency_index(std::span<const double> normalized_lengths);

}  // namespace quadval
