// The Bézier basis of the Jacobian space of one (family, order): a tensor product of
// Bernstein simplex factors, applied factor by factor. Thesis, Paper III §4.3, Table 1.
#include "quadval/bezier_basis.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>

#include "bezier/pyramid_basis.hpp"
#include "quadval/error.hpp"

namespace quadval {

std::vector<FactorDegree> jacobian_factor_degrees(ElementFamily family, int p) {
  switch (family) {
    case ElementFamily::line: return {{1, p - 1}};
    case ElementFamily::triangle: return {{2, 2 * (p - 1)}};
    case ElementFamily::quadrangle: return {{1, 2 * p - 1}, {1, 2 * p - 1}};
    case ElementFamily::tetrahedron: return {{3, 3 * (p - 1)}};
    case ElementFamily::prism: return {{2, 3 * p - 2}, {1, 3 * p - 1}};
    case ElementFamily::hexahedron: return {{1, 3 * p - 1}, {1, 3 * p - 1}, {1, 3 * p - 1}};
    case ElementFamily::pyramid: return pyramid_jacobian_factor_degrees(p);  // Paper IV eq. 6
    default: return {};
  }
}

int max_supported_order(ElementFamily family) noexcept {
  // The coefficients are Bernstein products of the geometry's control points
  // (src/analysis/jacobian_product.cpp), so the J space's conversion no longer limits us.
  // Lines, triangles and quadrangles: every order Gmsh defines (10). The a priori rounding
  // bound of the geometry's equispaced Lagrange-to-Bézier conversion grows with the order
  // (row sums ~1e3 at degree 9 per direction) but stays ~1e-12 of J: curved elements of
  // orders 9-10 made by Gmsh are all decided, as Gmsh decides them
  // (tests/analysis/gmsh_high_order_test.cpp). 3D: (1) memory: a tetrahedron of order 5
  // has a degree-12 factor of 455 coefficients, whose 8 subdivision matrices hold 1.7
  // million entries (and as many exact rationals); (2) time: prisms and hexahedra of
  // orders 5-6 build and bound correctly, but one subdivision of a 17^3-coefficient
  // hexahedron costs ~2 Mflop, too slow for the dense-sampling tests.
  switch (family) {
    case ElementFamily::line: return 10;
    case ElementFamily::triangle: return 10;
    case ElementFamily::quadrangle: return 10;
    case ElementFamily::tetrahedron: return 4;
    case ElementFamily::prism:
    case ElementFamily::hexahedron: return 4;
    case ElementFamily::pyramid: return kPyramidMaxOrder;
    default: return 0;
  }
}

BezierBasis::BezierBasis(ElementFamily family, int order,
                         std::vector<const BernsteinSimplex*> factors)
    : family_(family), order_(order), factors_(std::move(factors)) {
  QV_ASSERT(!factors_.empty() && factors_.size() <= 3, "1 to 3 factors");
  constexpr double u = std::numeric_limits<double>::epsilon() / 2;
  double rounding = 0;
  double subdivision = 0;
  for (const BernsteinSimplex* f : factors_) {
    dim_ += f->dim();
    size_ *= f->size();
    num_children_ *= f->num_children();
    // One pass: entries rounded to nearest (u) and an s-term dot product (gamma_s).
    rounding += u + rounding_gamma(f->size());
    subdivision += rounding_gamma(f->size());
  }
  // Cross terms between passes are second order: 1% covers them many times over.
  to_bezier_rounding_ = rounding * 1.01;
  subdivision_rounding_ = subdivision * 1.01;
  // V: nonnegative entries rounded to nearest (relative u), exact rows summing to 1, so a
  // pass keeps max|values| <= (1 + u)(1 + gamma_s) max|input| and adds u + gamma_s of it.
  from_bezier_rounding_ = rounding * 1.01;
  for (int i = 0; i < size_; ++i) {
    bool vertex = true;
    for (std::size_t f = 0; f < factors_.size(); ++f)
      vertex = vertex && factors_[f]->is_vertex(factor_index(i, static_cast<int>(f)));
    if (vertex) vertex_indices_.push_back(i);
  }
}

int BezierBasis::factor_index(int i, int f) const noexcept {
  for (int g = 0; g < f; ++g) i /= factors_[static_cast<std::size_t>(g)]->size();
  return i % factors_[static_cast<std::size_t>(f)]->size();
}

std::array<double, 3> BezierBasis::point(int i) const noexcept {
  std::array<double, 3> x{0, 0, 0};
  std::size_t c = 0;
  for (std::size_t f = 0; f < factors_.size(); ++f) {
    const auto p = factors_[f]->point(factor_index(i, static_cast<int>(f)));
    for (int k = 0; k < factors_[f]->dim(); ++k) x[c++] = p[static_cast<std::size_t>(k)];
  }
  return x;
}

std::array<int, 3> BezierBasis::child_digits(int child) const noexcept {
  std::array<int, 3> d{0, 0, 0};
  for (std::size_t f = 0; f < factors_.size(); ++f) {
    d[f] = child % factors_[f]->num_children();
    child /= factors_[f]->num_children();
  }
  return d;
}

void BezierBasis::evaluate(std::span<const double> x, std::span<double> values) const {
  QV_ASSERT(values.size() >= static_cast<std::size_t>(size_), "values too short");
  std::vector<std::vector<double>> fv(factors_.size());
  std::size_t c = 0;
  for (std::size_t f = 0; f < factors_.size(); ++f) {
    fv[f].resize(static_cast<std::size_t>(factors_[f]->size()));
    factors_[f]->evaluate(x.subspan(c), fv[f]);
    c += static_cast<std::size_t>(factors_[f]->dim());
  }
  for (int i = 0; i < size_; ++i) {
    double v = 1;
    for (std::size_t f = 0; f < factors_.size(); ++f)
      v *= fv[f][static_cast<std::size_t>(factor_index(i, static_cast<int>(f)))];
    values[static_cast<std::size_t>(i)] = v;
  }
}

// Applies matrix_of(f) (s_f x s_f, row-major) along axis f, for every factor in turn, to
// `count` interleaved arrays (element index fastest). Every output entry is the sum over
// j = 0 .. s_f - 1 in that order, whatever the loop nest, so results do not depend on
// `count`. When the contiguous run is 1 (one element, first factor) the loop runs over
// the output rows innermost with the transposed matrix, so that it vectorises.
template <class MatrixOf>
void BezierBasis::apply_factors(const double* in, double* out, double* scratch,
                                std::size_t count, MatrixOf matrix_of) const {
  const std::size_t nf = factors_.size();
  const std::size_t total = static_cast<std::size_t>(size_) * count;
  std::size_t stride = count;
  const double* src = in;
  for (std::size_t f = 0; f < nf; ++f) {
    const std::size_t s = static_cast<std::size_t>(factors_[f]->size());
    const std::size_t outer = total / (s * stride);
    double* dst = (f + 1 == nf) ? out : scratch + (f % 2) * total;
    const auto [m, mt] = matrix_of(f);  // row-major and its transpose
    for (std::size_t o = 0; o < outer; ++o) {
      const double* sblock = src + o * s * stride;
      double* dblock = dst + o * s * stride;
      if (stride == 1) {
        for (std::size_t a = 0; a < s; ++a) dblock[a] = 0;
        for (std::size_t j = 0; j < s; ++j) {
          const double v = sblock[j];
          const double* col = mt + j * s;  // column j of the matrix
          for (std::size_t a = 0; a < s; ++a) dblock[a] += col[a] * v;
        }
        continue;
      }
      for (std::size_t a = 0; a < s; ++a) {
        const double* row = m + a * s;
        double* d = dblock + a * stride;
        for (std::size_t i = 0; i < stride; ++i) d[i] = 0;
        for (std::size_t j = 0; j < s; ++j) {
          const double w = row[j];
          const double* sv = sblock + j * stride;
          for (std::size_t i = 0; i < stride; ++i) d[i] += w * sv[i];
        }
      }
    }
    src = dst;
    stride *= s;
  }
}

double BezierBasis::to_bezier_norm() const {
  std::call_once(norm_once_, [this] {
    double norm = 1;
    for (const BernsteinSimplex* f : factors_)  // the product of norms, each step rounded up
      norm = std::nextafter(norm * f->lagrange_to_bezier_norm(), std::numeric_limits<double>::infinity());
    to_bezier_norm_ = norm;
  });
  return to_bezier_norm_;
}

void BezierBasis::from_bezier_batch(const double* coeffs, std::size_t count, double* samples,
                                    double* scratch) const {
  apply_factors(coeffs, samples, scratch, count, [this](std::size_t f) {
    return std::pair{factors_[f]->bezier_to_lagrange().data(),
                     factors_[f]->bezier_to_lagrange_transposed().data()};
  });
}

void BezierBasis::to_bezier(const double* samples, double* coeffs, double* scratch) const {
  to_bezier_batch(samples, 1, coeffs, scratch);
}

void BezierBasis::to_bezier_batch(const double* samples, std::size_t count, double* coeffs,
                                  double* scratch) const {
  apply_factors(samples, coeffs, scratch, count, [this](std::size_t f) {
    return std::pair{factors_[f]->lagrange_to_bezier().data(),
                     factors_[f]->lagrange_to_bezier_transposed().data()};
  });
}

void BezierBasis::subdivide(int child, const double* parent, double* out,
                            double* scratch) const {
  const std::array<int, 3> digits = child_digits(child);
  apply_factors(parent, out, scratch, 1, [this, &digits](std::size_t f) {
    return std::pair{factors_[f]->subdivision(digits[f]).data(),
                     factors_[f]->subdivision_transposed(digits[f]).data()};
  });
}

void BezierBasis::subdivide_many(int child, const double* parents, std::size_t count,
                                 double* out, double* scratch) const {
  const auto s = static_cast<std::size_t>(size_);
  if (factors_.size() != 1) {  // tensor factors are small: one vector at a time
    for (std::size_t v = 0; v < count; ++v) subdivide(child, parents + v * s, out + v * s, scratch);
    return;
  }
  // As apply_factors' single-vector loop (out[a] += column j * parent[j], j increasing),
  // with the columns taken in blocks that every vector uses while they are in cache.
  const double* mt = factors_[0]->subdivision_transposed(child_digits(child)[0]).data();
  std::fill(out, out + s * count, 0.0);
  constexpr std::size_t kBlock = 32;
  for (std::size_t j0 = 0; j0 < s; j0 += kBlock) {
    const std::size_t j1 = std::min(s, j0 + kBlock);
    for (std::size_t v = 0; v < count; ++v) {
      double* d = out + v * s;
      const double* p = parents + v * s;
      for (std::size_t j = j0; j < j1; ++j) {
        const double w = p[j];
        const double* col = mt + j * s;
        for (std::size_t a = 0; a < s; ++a) d[a] += col[a] * w;
      }
    }
  }
}

const BezierBasis& bezier_basis(ElementFamily family, int order) {
  if (order < 1 || order > max_supported_order(family))
    throw std::invalid_argument("no Bézier Jacobian basis for " +
                                std::string(family_name(family)) + " of order " +
                                std::to_string(order));
  static std::mutex mutex;
  static std::map<std::pair<int, int>, std::unique_ptr<const BezierBasis>> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[{static_cast<int>(family), order}];
  if (!slot) {
    std::vector<const BernsteinSimplex*> factors;
    for (const FactorDegree& fd : jacobian_factor_degrees(family, order))
      factors.push_back(&bernstein_simplex(fd.dim, fd.degree));
    slot = std::make_unique<const BezierBasis>(family, order, std::move(factors));
  }
  return *slot;
}

}  // namespace quadval
