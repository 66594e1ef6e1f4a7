// Jacobian Bézier coefficients by Bernstein products (see jacobian_product.hpp).
//
// Error model, per element (u = 2^-53; N nodes read; R_j = max_i |x_ij - x_0j| computed):
//   derivative control points: d^_k = sum_i G^_ki (x_i - x_0), G^ rounded to nearest from the
//     exact rational (relative u, counted 2u), coordinates differenced (u):
//       |d^~_k - d^_k| <= mult(k) delta_j,  delta_j = (4u + gamma_N) Gamma R_j,
//     Gamma = max_k sum_i |G^_ki| / mult(k) (exact, rounded up);
//   magnitudes: A_cj = max_k |d^~_ckj| / mult(k) (1 + 4u) + delta_cj bounds the computed
//     and the exact unscaled coefficient of direction c, coordinate j;
//   products (scaled convolutions, any order of summation, Higham §3.1): the computed
//     J^_gamma is within gamma_K of sum |terms| <= mult(gamma) sum_perm A B C, K the number
//     of products reaching one coefficient (3D: 3 T2 + 2 T1; T1, T2 the terms per output
//     coefficient of the two convolutions); the final scaling by fl(1/mult) adds 2u;
//   input errors: sum_perm (delta_a B C + A delta_b C + A B delta_c), the same in 2D with
//     |n_i| in place of one factor, and in 1D sum_j |t_j| delta_j.
// Each bound is multiplied by 1.01, which covers the rounding of the bound itself.
// The kernel (lane_block) computes kLanes elements per SIMD lane block but, per element, the
// same sums in the same order as one element alone (no FMA: -ffp-contract=off), so the
// model above, which allows any summation order, holds unchanged. Its loops over the lanes
// carry `omp simd`: without it GCC 12 unrolled them into scalar code (measured: 2x slower
// on order-4 triangles, 2.9x on order-2 hexahedra). The products' accumulators are
// Lanes<W> vectors: as arrays, GCC 12 kept them on the stack, a store and a reload per term.
#include "analysis/jacobian_product.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <tuple>

#include "analysis/exact_inverse.hpp"
#include "analysis/factor_shapes.hpp"
#include "analysis/jacobian_samples.hpp"
#include "analysis/lane_vector.hpp"
#include "analysis/product_tables.hpp"
#include "analysis/pyramid_space.hpp"
#include "bezier/bezier_exact.hpp"
#include "bezier/multi_index_table.hpp"
#include "bezier/rational_rounding.hpp"
#include "mesh/polynomial_space.hpp"
#include "quadval/error.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

using MultiIndex = std::array<int, 4>;
constexpr double kUnit = 0x1p-53;


int index_of(const std::vector<MultiIndex>& list, const MultiIndex& a) {
  const auto it = std::find(list.begin(), list.end(), a);
  QV_ASSERT(it != list.end(), "multi-index outside the space");
  return static_cast<int>(it - list.begin());
}

mpz_class factorial(int n) {
  mpz_class f = 1;
  for (int i = 2; i <= n; ++i) f *= i;
  return f;
}

mpz_class multinomial(const MultiIndex& a) {
  mpz_class r = factorial(a[0] + a[1] + a[2] + a[3]);
  for (int x : a) r /= factorial(x);
  return r;
}

mpq_class frac(long n, long d) {
  mpq_class q(n, d);
  q.canonicalize();
  return q;
}

// Multi-indices of degree n in d + 1 components: binomial(n + d, d).
int simplex_size(int d, int n) {
  int size = 1;
  for (int k = 1; k <= d; ++k) size = size * (n + k) / k;  // exact at every step
  return size;
}

// A Gmsh reference coordinate snapped to the order-p lattice (numerator over p).
int snap(double x, int p, bool interval) {
  const double t = interval ? (x + 1) * 0.5 * p : x * p;
  const double m = std::round(t);
  QV_ASSERT(std::abs(t - m) < 1e-9, "reference node " << x << " off the order-" << p << " lattice");
  return static_cast<int>(m);
}

}  // namespace

JacobianProduct::JacobianProduct(const ElementType& type, const BezierBasis& basis,
                                 TableSource source)
    : type_(&type), basis_(&basis), dim_(type.dim), order_(type.order) {
  if (type.family == ElementFamily::pyramid) {
    init_pyramid(source);  // src/analysis/pyramid_space.cpp
    build_sparse_rows();
    return;
  }
  const auto shapes = factor_shapes(type.family);
  QV_ASSERT(!shapes.empty() && type.has_lagrange_basis, "no Bernstein product for " << type.name);
  const int p = order_;
  num_factors_ = static_cast<int>(shapes.size());
  for (int h = 0; h < num_factors_; ++h) {
    const auto hs = static_cast<std::size_t>(h);
    factor_dim_[hs] = shapes[hs].dim;
    factor_first_[hs] = shapes[hs].first;
    factor_interval_[hs] = shapes[hs].interval;
    for (int c = 0; c < shapes[hs].dim; ++c) {
      direction_factor_[static_cast<std::size_t>(shapes[hs].first + c)] = h;
      direction_local_[static_cast<std::size_t>(shapes[hs].first + c)] = c + 1;
    }
  }
  const auto space_of = [&](std::array<int, 3> degree) {
    Space s;
    s.degree = degree;
    s.total = 1;
    for (int h = 0; h < 3; ++h) {
      const auto hs = static_cast<std::size_t>(h);
      s.size[hs] = h < num_factors_ ? simplex_size(factor_dim_[hs], degree[hs]) : 1;
      s.total *= s.size[hs];
    }
    return s;
  };
  lattice_ = space_of({p, p, p});

  // Direction c's derivative space: degree p - 1 in its own factor, p in the others.
  for (int c = 0; c < dim_; ++c) {
    const auto cs = static_cast<std::size_t>(c);
    std::array<int, 3> deg{p, p, p};
    deg[static_cast<std::size_t>(direction_factor_[cs])] = p - 1;
    deriv_space_[cs] = space_of(deg);
  }

  // The J space: it must be the basis's, factor by factor, in the same enumeration.
  std::array<int, 3> jdeg{0, 0, 0};
  for (int h = 0; h < num_factors_; ++h) {
    const auto hs = static_cast<std::size_t>(h);
    for (int c = 0; c < dim_; ++c) jdeg[hs] += deriv_space_[static_cast<std::size_t>(c)].degree[hs];
    QV_ASSERT(basis.factors()[hs]->degree() == jdeg[hs] && basis.factors()[hs]->dim() == factor_dim_[hs],
              "J space of " << type.name << " differs from its basis");
  }
  const Space jspace = space_of(jdeg);
  QV_ASSERT(jspace.total == basis.size(), "J space size");

  Space bcs;  // 3D: the space of X_eta x X_zeta
  if (dim_ == 3) {
    std::array<int, 3> bc{0, 0, 0};
    for (std::size_t h = 0; h < 3; ++h) bc[h] = deriv_space_[1].degree[h] + deriv_space_[2].degree[h];
    bcs = space_of(bc);
    cross_size_ = bcs.total;
  }
  maps_[0].num_nodes = type.num_nodes;
  maps_[1].num_nodes = family_num_vertices(type.family);

  // The tables: generated at build time for common types (product_tables.hpp), else made
  // here, the rounded ones from the exact data, which the generated path builds only when
  // the exact fallback first asks for it (exact_coefficients).
  const ProductTableView* generated =
      source == TableSource::generated_or_exact ? generated_product_tables(type.gmsh_id) : nullptr;
  if (generated != nullptr) {
    load_tables(*generated);
    if (cross_gather_.first.empty()) build_products(bcs, jspace);  // not generated (large)
  } else {
    build_products(bcs, jspace);
    if (type.complete) build_lattice_of_node();
    build_exact();
    build_rounded_tables();
  }
  build_sparse_rows();
}

void JacobianProduct::build_products(const Space& bcs, const Space& jspace) {
  // The convolutions, and the rounding constant of the model above.
  if (dim_ == 3) {
    const Product cross = make_product(deriv_space_[1], deriv_space_[2], bcs);
    const Product dot = make_product(deriv_space_[0], bcs, jspace);
    cross_gather_ = make_gather(cross, cross_size_);
    dot_gather_ = make_gather(dot, jspace.total);
    rounding_ = rounding_gamma(3 * dot.max_terms + 2 * cross.max_terms) + 2.01 * kUnit;
  } else if (dim_ == 2) {
    const Product cross = make_product(deriv_space_[0], deriv_space_[1], jspace);
    cross_gather_ = make_gather(cross, jspace.total);
    rounding_ = rounding_gamma(8 * cross.max_terms + 8) + 2.01 * kUnit;
  } else {
    rounding_ = rounding_gamma(4) + 2.01 * kUnit;
  }
}

// Node i of a complete type sits at a lattice point.
void JacobianProduct::build_lattice_of_node() {
  const int p = order_;
  const auto ref = reference_nodes(*type_);
  lattice_of_node_.resize(ref.size());
  for (std::size_t i = 0; i < ref.size(); ++i) {
    int l = 0, stride = 1;
    for (int h = 0; h < num_factors_; ++h) {
      const auto hs = static_cast<std::size_t>(h);
      MultiIndex a{0, 0, 0, 0};
      int sum = 0;
      for (int c = 0; c < factor_dim_[hs]; ++c) {
        a[static_cast<std::size_t>(c + 1)] =
            snap(ref[i][static_cast<std::size_t>(factor_first_[hs] + c)], p, factor_interval_[hs]);
        sum += a[static_cast<std::size_t>(c + 1)];
      }
      a[0] = p - sum;
      l += stride * index_of(simplex_multi_indices(factor_dim_[hs], p), a);
      stride *= lattice_.size[hs];
    }
    lattice_of_node_[i] = l;
  }
}

void JacobianProduct::build_exact() const {
  std::call_once(exact_once_, [this] { build_exact_data(); });
}

void JacobianProduct::build_exact_data() const {
  if (type_->family == ElementFamily::pyramid) {
    build_pyramid_exact_data();
    return;
  }
  const int p = order_;
  const BezierBasis& basis = *basis_;
  // Exact per-factor derivative maps (scaled rows): factor h != f(c): mult(a) T_h[a][l];
  // factor f(c): mult(b) s p (T[b + e_c][l] - T[b + e_0][l]), s = 1/2 on [-1, 1] axes.
  for (int c = 0; c < dim_; ++c) {
    const auto cs = static_cast<std::size_t>(c);
    const int f = direction_factor_[cs];
    for (int h = 0; h < num_factors_; ++h) {
      const auto hs = static_cast<std::size_t>(h);
      const int d = factor_dim_[hs];
      const BernsteinSimplex& geo = bernstein_simplex(d, p);
      const auto& t = geo.exact().to_bezier;
      const auto lat = simplex_multi_indices(d, p);
      const auto ls = lat.size();
      auto& m = factor_matrix_[cs][hs];
      if (h != f) {
        m.resize(ls * ls);
        for (std::size_t a = 0; a < ls; ++a)
          for (std::size_t l = 0; l < ls; ++l) m[a * ls + l] = multinomial(lat[a]) * t[a * ls + l];
      } else {
        const auto rows = simplex_multi_indices(d, p - 1);
        m.resize(rows.size() * ls);
        const mpq_class scale = factor_interval_[hs] ? frac(p, 2) : mpq_class(p);
        const int local = direction_local_[cs];
        for (std::size_t b = 0; b < rows.size(); ++b) {
          MultiIndex plus = rows[b], zero = rows[b];
          ++plus[static_cast<std::size_t>(local)];
          ++zero[0];
          const auto ip = static_cast<std::size_t>(index_of(lat, plus));
          const auto iz = static_cast<std::size_t>(index_of(lat, zero));
          const mpq_class w = scale * multinomial(rows[b]);
          for (std::size_t l = 0; l < ls; ++l) m[b * ls + l] = w * (t[ip * ls + l] - t[iz * ls + l]);
        }
      }
    }
  }
  // mult(gamma) of the J space.
  mult_.resize(static_cast<std::size_t>(basis.size()));
  for (int k = 0; k < basis.size(); ++k) {
    mpz_class w = 1;
    for (int h = 0; h < num_factors_; ++h)
      w *= multinomial(basis.factors()[static_cast<std::size_t>(h)]->multi_indices()[static_cast<std::size_t>(basis.factor_index(k, h))]);
    mult_[static_cast<std::size_t>(k)] = w;
  }
  build_lattice_values(SampleMap::curved);
  build_lattice_values(SampleMap::straight);
}

void JacobianProduct::build_rounded_tables() {
  // 1 / mult(k) of the derivative spaces and of the J space, rounded to nearest.
  for (int c = 0; c < dim_; ++c) {
    const auto cs = static_cast<std::size_t>(c);
    const std::array<int, 3> deg = deriv_space_[cs].degree;
    auto& inv = deriv_inv_mult_[cs];
    inv.resize(static_cast<std::size_t>(deriv_space_[cs].total));
    for (int k = 0; k < deriv_space_[cs].total; ++k) {
      mpz_class w = 1;
      int rest = k;
      for (int h = 0; h < num_factors_; ++h) {
        const auto hs = static_cast<std::size_t>(h);
        const auto idx = simplex_multi_indices(factor_dim_[hs], deg[hs]);
        w *= multinomial(idx[static_cast<std::size_t>(rest % deriv_space_[cs].size[hs])]);
        rest /= deriv_space_[cs].size[hs];
      }
      inv[static_cast<std::size_t>(k)] = nearest_double(mpq_class(1) / mpq_class(w));
    }
  }
  inv_mult_.resize(mult_.size());
  for (std::size_t k = 0; k < mult_.size(); ++k) inv_mult_[k] = nearest_double(mpq_class(1) / mpq_class(mult_[k]));
  build_map_tables(SampleMap::curved);
  build_map_tables(SampleMap::straight);
}

ProductTables JacobianProduct::tables() const {
  ProductTables t;
  for (std::size_t m = 0; m < 2; ++m) {
    t.maps[m].num_nodes = maps_[m].num_nodes;
    t.maps[m].matrix = maps_[m].matrix;
    t.maps[m].row_sum = maps_[m].row_sum;
  }
  t.deriv_inv_mult = deriv_inv_mult_;
  t.inv_mult = inv_mult_;
  t.rounding = rounding_;
  t.lattice_of_node = lattice_of_node_;
  const Gather* gathers[2] = {&cross_gather_, &dot_gather_};
  for (std::size_t g = 0; g < 2; ++g) {
    t.gather_first[g] = gathers[g]->first;
    for (const auto& [a, b] : gathers[g]->terms) t.gather_terms[g].insert(t.gather_terms[g].end(), {a, b});
  }
  return t;
}

void JacobianProduct::load_tables(const ProductTableView& g) {
  const auto expect_size = [&](std::span<const double> v, std::size_t n) {
    QV_ASSERT(v.size() == n, "generated tables of " << type_->name << " have " << v.size() << " entries, expected " << n);
    return std::vector<double>(v.begin(), v.end());
  };
  for (std::size_t m = 0; m < 2; ++m) {
    Map& map = maps_[m];
    QV_ASSERT(g.num_nodes[m] == map.num_nodes, "generated tables of " << type_->name << ": node count");
    for (int c = 0; c < dim_; ++c) {
      const auto cs = static_cast<std::size_t>(c);
      map.matrix[cs] = expect_size(g.matrix[m][cs], static_cast<std::size_t>(deriv_space_[cs].total) * static_cast<std::size_t>(map.num_nodes));
      map.row_sum[cs] = g.row_sum[m][cs];
    }
  }
  for (int c = 0; c < dim_; ++c) {
    const auto cs = static_cast<std::size_t>(c);
    deriv_inv_mult_[cs] = expect_size(g.deriv_inv_mult[cs], static_cast<std::size_t>(deriv_space_[cs].total));
  }
  inv_mult_ = expect_size(g.inv_mult, static_cast<std::size_t>(basis_->size()));
  rounding_ = g.rounding;
  lattice_of_node_.assign(g.lattice_of_node.begin(), g.lattice_of_node.end());
  QV_ASSERT(lattice_of_node_.size() == (type_->complete && type_->family != ElementFamily::pyramid
                                            ? static_cast<std::size_t>(type_->num_nodes) : 0),
            "generated tables of " << type_->name << ": lattice of the nodes");
  Gather* gathers[2] = {&cross_gather_, &dot_gather_};
  const int outputs[2] = {dim_ == 3 ? cross_size_ : basis_->size(), dim_ == 3 ? basis_->size() : 0};
  // Gathers: none generated for large types (the constructor builds them), else both.
  for (std::size_t k = 0; k < 2 && !g.gather_first[0].empty(); ++k) {
    Gather& gather = *gathers[k];
    const std::span<const int> first = g.gather_first[k];
    const std::span<const int> terms = g.gather_terms[k];
    const bool used = k == 0 ? dim_ >= 2 : dim_ == 3;
    QV_ASSERT(used ? first.size() == static_cast<std::size_t>(outputs[k]) + 1 && first.back() * 2 == static_cast<int>(terms.size())
                   : first.empty() && terms.empty(),
              "generated tables of " << type_->name << ": gather " << k);
    gather.first.assign(first.begin(), first.end());
    gather.terms.resize(terms.size() / 2);
    for (std::size_t t = 0; t < gather.terms.size(); ++t) gather.terms[t] = {terms[2 * t], terms[2 * t + 1]};
  }
}

JacobianProduct::Product JacobianProduct::make_product(const Space& a, const Space& b,
                                                       const Space& c) const {
  Product p;
  p.max_terms = 1;
  int sa = 1, sb = 1, sc = 1;
  for (int h = 0; h < 3; ++h) {
    const auto hs = static_cast<std::size_t>(h);
    p.stride_a[hs] = sa, p.stride_b[hs] = sb, p.stride_c[hs] = sc;
    sa *= a.size[hs], sb *= b.size[hs], sc *= c.size[hs];
    if (h >= num_factors_) {
      p.pairs[hs] = {{0, 0, 0}};
      continue;
    }
    const int d = factor_dim_[hs];
    const auto ia = simplex_multi_indices(d, a.degree[hs]), ib = simplex_multi_indices(d, b.degree[hs]),
               ic = simplex_multi_indices(d, c.degree[hs]);
    std::vector<int> terms(ic.size(), 0);
    const MultiIndexTable where(ic, c.degree[hs]);
    for (std::size_t x = 0; x < ia.size(); ++x)
      for (std::size_t y = 0; y < ib.size(); ++y) {
        MultiIndex s;
        for (std::size_t k = 0; k < 4; ++k) s[k] = ia[x][k] + ib[y][k];
        const int z = where(s);
        QV_ASSERT(z >= 0 && ic[static_cast<std::size_t>(z)] == s, "multi-index outside the product space");
        p.pairs[hs].push_back({static_cast<int>(x), static_cast<int>(y), z});
        ++terms[static_cast<std::size_t>(z)];
      }
    // Sorted by output then inputs: a fixed summation order, and locality of the output.
    std::sort(p.pairs[hs].begin(), p.pairs[hs].end(),
              [](const Pair& l, const Pair& r) { return std::tie(l.c, l.a, l.b) < std::tie(r.c, r.a, r.b); });
    p.max_terms *= *std::max_element(terms.begin(), terms.end());
  }
  return p;
}

template <class F>
void JacobianProduct::for_each_term(const Gather& g, F&& f) {
  for (std::size_t k = 0; k + 1 < g.first.size(); ++k)
    for (int t = g.first[k]; t < g.first[k + 1]; ++t)
      f(g.terms[static_cast<std::size_t>(t)][0], g.terms[static_cast<std::size_t>(t)][1], static_cast<int>(k));
}

template <class F>
void JacobianProduct::for_each_term(const Product& p, F&& f) {
  for (const Pair& t2 : p.pairs[2])
    for (const Pair& t1 : p.pairs[1])
      for (const Pair& t0 : p.pairs[0])
        f(t0.a * p.stride_a[0] + t1.a * p.stride_a[1] + t2.a * p.stride_a[2],
          t0.b * p.stride_b[0] + t1.b * p.stride_b[1] + t2.b * p.stride_b[2],
          t0.c * p.stride_c[0] + t1.c * p.stride_c[1] + t2.c * p.stride_c[2]);
}

std::vector<mpq_class> JacobianProduct::exact_derivative(int c, const std::vector<mpq_class>& values) const {
  const auto cs = static_cast<std::size_t>(c);
  std::vector<mpq_class> in = values, out;
  std::array<int, 3> dims = lattice_.size;
  for (int h = 0; h < num_factors_; ++h) {
    const auto hs = static_cast<std::size_t>(h);
    const auto& m = factor_matrix_[cs][hs];
    const auto cols = static_cast<std::size_t>(lattice_.size[hs]);
    const auto rows = static_cast<std::size_t>(deriv_space_[cs].size[hs]);
    std::size_t inner = 1, outer = 1;
    for (int g = 0; g < h; ++g) inner *= static_cast<std::size_t>(dims[static_cast<std::size_t>(g)]);
    for (int g = h + 1; g < 3; ++g) outer *= static_cast<std::size_t>(dims[static_cast<std::size_t>(g)]);
    out.assign(inner * rows * outer, mpq_class(0));
    for (std::size_t o = 0; o < outer; ++o)
      for (std::size_t r = 0; r < rows; ++r)
        for (std::size_t l = 0; l < cols; ++l) {
          const mpq_class& w = m[r * cols + l];
          if (sgn(w) == 0) continue;
          for (std::size_t i = 0; i < inner; ++i)
            out[(o * rows + r) * inner + i] += w * in[(o * cols + l) * inner + i];
        }
    in.swap(out);
    dims[hs] = static_cast<int>(rows);
  }
  return in;
}

void JacobianProduct::build_lattice_values(SampleMap which) const {
  Map& map = maps_[static_cast<std::size_t>(which)];
  const int p = order_;
  const auto lat = static_cast<std::size_t>(lattice_.total);
  // Exact nodal values on the complete lattice of the N nodes' shape functions.
  if (which == SampleMap::straight) {
    const ElementType& linear = *find_element_type(type_->family, 1, true);
    const auto ref = reference_nodes(linear);
    map.to_lattice.assign(lat * ref.size(), mpq_class(0));
    for (std::size_t v = 0; v < ref.size(); ++v) {
      // vertex v: which barycentric component is 1 in each factor
      std::array<int, 3> corner{0, 0, 0};
      for (int h = 0; h < num_factors_; ++h) {
        const auto hs = static_cast<std::size_t>(h);
        int sum = 0;
        for (int c = 0; c < factor_dim_[hs]; ++c) {
          const int a = snap(ref[v][static_cast<std::size_t>(factor_first_[hs] + c)], 1, factor_interval_[hs]);
          if (a == 1) corner[hs] = c + 1;
          sum += a;
        }
        if (sum == 0) corner[hs] = 0;
      }
      for (std::size_t l = 0; l < lat; ++l) {
        mpq_class value = 1;
        std::size_t rest = l;
        for (int h = 0; h < num_factors_; ++h) {
          const auto hs = static_cast<std::size_t>(h);
          const auto idx = simplex_multi_indices(factor_dim_[hs], p);
          const MultiIndex& a = idx[rest % idx.size()];
          rest /= idx.size();
          value *= frac(a[static_cast<std::size_t>(corner[hs])], p);
        }
        map.to_lattice[l * ref.size() + v] = value;
      }
    }
  } else if (!type_->complete) {
    // Serendipity: N_n at the lattice points, from the exact inverse of the Vandermonde
    // matrix of the type's monomial space (Gmsh coordinates).
    const detail::PolynomialSpace space = detail::polynomial_space(*type_, detail::FactorBasis::monomial);
    const auto ref = reference_nodes(*type_);
    const std::size_t n = ref.size();
    const auto power = [](const mpq_class& x, int e) {
      mpq_class r = 1;
      for (int k = 0; k < e; ++k) r *= x;
      return r;
    };
    const auto gmsh_coord = [&](int axis, int numerator) {
      const mpq_class t = frac(numerator, p);
      return factor_interval_[static_cast<std::size_t>(direction_factor_[static_cast<std::size_t>(axis)])] ? 2 * t - 1 : t;
    };
    const auto monomials = [&](const std::array<mpq_class, 3>& x) {
      std::vector<mpq_class> phi(n);
      for (std::size_t j = 0; j < n; ++j) {
        mpq_class v = 1;
        for (int c = 0; c < dim_; ++c) v *= power(x[static_cast<std::size_t>(c)], space.exponents[j][static_cast<std::size_t>(c)]);
        phi[j] = v;
      }
      return phi;
    };
    std::vector<mpq_class> v(n * n);
    for (std::size_t i = 0; i < n; ++i) {
      std::array<mpq_class, 3> x{0, 0, 0};
      for (int c = 0; c < dim_; ++c) {
        const bool interval = factor_interval_[static_cast<std::size_t>(direction_factor_[static_cast<std::size_t>(c)])];
        x[static_cast<std::size_t>(c)] = gmsh_coord(c, snap(ref[i][static_cast<std::size_t>(c)], p, interval));
      }
      const auto phi = monomials(x);
      std::copy(phi.begin(), phi.end(), v.begin() + static_cast<std::ptrdiff_t>(i * n));
    }
    const std::vector<mpq_class> inv = exact_inverse(std::move(v), n, *type_);  // N_i = sum_j phi_j inv[j][i]
    map.to_lattice.assign(lat * n, mpq_class(0));
    for (std::size_t l = 0; l < lat; ++l) {
      std::array<mpq_class, 3> x{0, 0, 0};
      std::size_t rest = l;
      for (int h = 0; h < num_factors_; ++h) {
        const auto hs = static_cast<std::size_t>(h);
        const auto idx = simplex_multi_indices(factor_dim_[hs], p);
        const MultiIndex& a = idx[rest % idx.size()];
        rest /= idx.size();
        for (int c = 0; c < factor_dim_[hs]; ++c)
          x[static_cast<std::size_t>(factor_first_[hs] + c)] = gmsh_coord(factor_first_[hs] + c, a[static_cast<std::size_t>(c + 1)]);
      }
      const auto phi = monomials(x);
      for (std::size_t i = 0; i < n; ++i) {
        mpq_class s = 0;
        for (std::size_t j = 0; j < n; ++j)
          if (sgn(phi[j]) != 0 && sgn(inv[j * n + i]) != 0) s += phi[j] * inv[j * n + i];
        map.to_lattice[l * n + i] = s;
      }
    }
  }
}

void JacobianProduct::build_map_tables(SampleMap which) {
  Map& map = maps_[static_cast<std::size_t>(which)];
  // Rounded derivative maps and their row sums.
  const auto n = static_cast<std::size_t>(map.num_nodes);
  const auto lat = static_cast<std::size_t>(lattice_.total);
  for (int c = 0; c < dim_; ++c) {
    const auto cs = static_cast<std::size_t>(c);
    const auto rows = static_cast<std::size_t>(deriv_space_[cs].total);
    std::vector<mpq_class> row_abs(rows, mpq_class(0));
    auto& g = map.matrix[cs];
    g.assign(rows * n, 0.0);
    const auto store = [&](std::size_t k, std::size_t i, const mpq_class& q) {
      g[k * n + i] = nearest_double(q);
      row_abs[k] += abs(q);
    };
    if (map.to_lattice.empty()) {
      // complete: entry = product of the factor entries at the node's lattice point
      for (std::size_t i = 0; i < n; ++i) {
        std::array<std::size_t, 3> l{0, 0, 0};
        std::size_t rest = static_cast<std::size_t>(lattice_of_node_[i]);
        for (int h = 0; h < num_factors_; ++h) {
          l[static_cast<std::size_t>(h)] = rest % static_cast<std::size_t>(lattice_.size[static_cast<std::size_t>(h)]);
          rest /= static_cast<std::size_t>(lattice_.size[static_cast<std::size_t>(h)]);
        }
        for (std::size_t k = 0; k < rows; ++k) {
          mpq_class e = 1;
          std::size_t kr = k;
          for (int h = 0; h < num_factors_; ++h) {
            const auto hs = static_cast<std::size_t>(h);
            const auto r = static_cast<std::size_t>(deriv_space_[cs].size[hs]);
            e *= factor_matrix_[cs][hs][(kr % r) * static_cast<std::size_t>(lattice_.size[hs]) + l[hs]];
            kr /= r;
            if (sgn(e) == 0) break;
          }
          store(k, i, e);
        }
      }
    } else {
      std::vector<mpq_class> column(lat);
      for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t l = 0; l < lat; ++l) column[l] = map.to_lattice[l * n + i];
        const std::vector<mpq_class> d = exact_derivative(c, column);
        for (std::size_t k = 0; k < rows; ++k) store(k, i, d[k]);
      }
    }
    mpq_class worst = 0;
    for (std::size_t k = 0; k < rows; ++k) {
      const mpq_class r = row_abs[k] * mpq_class(deriv_inv_mult_[cs][k]) * (1 + mpq_class(1, 1 << 20));
      worst = std::max(worst, r);
    }
    map.row_sum[cs] = round_up(worst);
  }
}

JacobianProduct::Gather JacobianProduct::make_gather(const Product& p, int outputs) const {
  // Bucket the terms by output, keeping for_each_term's order within each output: a
  // counting sort (two passes, two allocations; a vector per output was most of the
  // set-up time of a type with generated tables).
  const auto outs = static_cast<std::size_t>(outputs);
  Gather g;
  g.first.assign(outs + 1, 0);
  for_each_term(p, [&](int, int, int c) { ++g.first[static_cast<std::size_t>(c) + 1]; });
  for (std::size_t k = 0; k < outs; ++k) g.first[k + 1] += g.first[k];
  g.terms.resize(static_cast<std::size_t>(g.first[outs]));
  std::vector<int> fill(g.first.begin(), g.first.end() - 1);
  for_each_term(p, [&](int a, int b, int c) { g.terms[static_cast<std::size_t>(fill[static_cast<std::size_t>(c)]++)] = {a, b}; });
  return g;
}

void JacobianProduct::build_sparse_rows() {
  for (Map& map : maps_) {
    const auto n = static_cast<std::size_t>(map.num_nodes);
    for (int c = 0; c < dim_; ++c) {
      const auto cs = static_cast<std::size_t>(c);
      map.rows[cs] = SparseRows::of(map.matrix[cs], static_cast<std::size_t>(deriv_space_[cs].total), n);
    }
  }
}

std::size_t JacobianProduct::block_size(const Map& map, int lanes) const {
  std::size_t doubles = static_cast<std::size_t>(map.num_nodes) * 3 + 3;  // coordinates, ranges
  for (int c = 0; c < dim_; ++c) doubles += static_cast<std::size_t>(deriv_space_[static_cast<std::size_t>(c)].total) * 3 + 3;
  doubles += static_cast<std::size_t>(cross_size_) * 3 + 3;  // cross products; reference vectors
  return doubles * static_cast<std::size_t>(lanes);
}

// One lane block: element l of the block at nodes + l * stride. Every array is
// [quantity][lane], so each loop over l is one vector operation, and lane l performs
// exactly the operations, in exactly the order, of an element computed alone (W = 1):
// fp-contract is off, so no fused multiply-add can make the two differ.
template <int W>
void JacobianProduct::lane_block(const Map& map, const double* nodes, std::size_t stride,
                                 bool planar, double* coeffs, double* errors, double* buf) const {
  const auto n = static_cast<std::size_t>(map.num_nodes);
  const auto S = static_cast<std::size_t>(basis_->size());
  constexpr std::size_t w = W;

  // Coordinates relative to each element's first node, and their ranges R_j. A planar 2D
  // J = x_xi y_eta - x_eta y_xi takes no z: neither its derivatives nor, below, its error
  // bound (the reference direction n = +z weighs only the x, y terms).
  const std::size_t axes = dim_ == 2 && planar ? 2 : 3;
  double* x = buf;
  double* range = x + n * 3 * w;
  for (std::size_t l = 0; l < w; ++l) {
    const double* xe = nodes + l * stride;
    // Three scalars, not an array: GCC 12 kept an array of ranges on the stack.
    double r0 = 0, r1 = 0, r2 = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double d0 = xe[3 * i] - xe[0], d1 = xe[3 * i + 1] - xe[1];
      x[(i * 3) * w + l] = d0;
      x[(i * 3 + 1) * w + l] = d1;
      r0 = std::max(r0, std::abs(d0));
      r1 = std::max(r1, std::abs(d1));
      if (axes == 3) {
        const double d2 = xe[3 * i + 2] - xe[2];
        x[(i * 3 + 2) * w + l] = d2;
        r2 = std::max(r2, std::abs(d2));
      }
    }
    range[l] = r0;
    range[w + l] = r1;
    range[2 * w + l] = r2;
  }

  // Derivative control points, scaled: d_ckj = sum_i G^_ki x_ij over the nonzero G^_ki in
  // ascending i; and their magnitudes max_k |d_ckj| / mult(k) for the error bound.
  std::array<double*, 3> deriv{nullptr, nullptr, nullptr};
  double big[3][3][W] = {};
  double* next = range + 3 * w;
  for (int c = 0; c < dim_; ++c) {
    const auto cs = static_cast<std::size_t>(c);
    const SparseRows& r = map.rows[cs];
    const auto rows = static_cast<std::size_t>(deriv_space_[cs].total);
    double* d = deriv[cs] = next;
    next += rows * 3 * w;
    // All axes in one walk over the row's nonzeros (each axis's sum in the same order).
    const auto derive = [&]<std::size_t kAxes>() {
      for (std::size_t k = 0; k < rows; ++k) {
        const double inv = deriv_inv_mult_[cs][k];
        double acc[kAxes][W] = {};
        for (std::uint32_t t = r.start[k]; t < r.start[k + 1]; ++t) {
          const double g = r.value[t];
          const double* xi = x + static_cast<std::size_t>(r.node[t]) * 3 * w;
          for (std::size_t j = 0; j < kAxes; ++j) {
            #pragma omp simd
            for (std::size_t l = 0; l < w; ++l) acc[j][l] += g * xi[j * w + l];
          }
        }
        for (std::size_t j = 0; j < kAxes; ++j)
          for (std::size_t l = 0; l < w; ++l) {
            d[(k * 3 + j) * w + l] = acc[j][l];
            big[c][j][l] = std::max(big[c][j][l], std::abs(acc[j][l]) * inv);
          }
      }
    };
    if (axes == 2)
      derive.template operator()<2>();
    else
      derive.template operator()<3>();
  }

  // Products, then J_gamma = J^_gamma / mult(gamma), written element-major.
  using V = Lanes<W>;
  const auto store = [&](std::size_t k, const V& acc) {
    const V scaled = acc * inv_mult_[k];
    for (std::size_t l = 0; l < w; ++l) coeffs[l * S + k] = scaled[l];
  };
  double* refs = next;  // 1D, 2D: the reference vector of each lane, [j][lane]
  if (dim_ < 3)
    for (std::size_t l = 0; l < w; ++l) {
      const auto t = reference_direction(*type_, nodes + l * stride, planar);
      for (std::size_t j = 0; j < 3; ++j) refs[j * w + l] = t[j];
    }
  if (dim_ == 3) {
    const double* d1 = deriv[1];
    const double* d2 = deriv[2];
    double* cr = next;
    for (std::size_t m = 0; m + 1 < cross_gather_.first.size(); ++m) {
      V a0{}, a1{}, a2{};
      for (int t = cross_gather_.first[m]; t < cross_gather_.first[m + 1]; ++t) {
        const auto& term = cross_gather_.terms[static_cast<std::size_t>(t)];
        const double* b = d1 + static_cast<std::size_t>(term[0]) * 3 * w;
        const double* c = d2 + static_cast<std::size_t>(term[1]) * 3 * w;
        const V b0 = load_lanes<W>(b), b1 = load_lanes<W>(b + w), b2 = load_lanes<W>(b + 2 * w);
        const V c0 = load_lanes<W>(c), c1 = load_lanes<W>(c + w), c2 = load_lanes<W>(c + 2 * w);
        a0 += b1 * c2 - b2 * c1;
        a1 += b2 * c0 - b0 * c2;
        a2 += b0 * c1 - b1 * c0;
      }
      std::memcpy(cr + (m * 3) * w, &a0, sizeof a0);
      std::memcpy(cr + (m * 3 + 1) * w, &a1, sizeof a1);
      std::memcpy(cr + (m * 3 + 2) * w, &a2, sizeof a2);
    }
    const double* d0 = deriv[0];
    for (std::size_t k = 0; k < S; ++k) {
      V acc{};
      for (int t = dot_gather_.first[k]; t < dot_gather_.first[k + 1]; ++t) {
        const auto& term = dot_gather_.terms[static_cast<std::size_t>(t)];
        const double* a = d0 + static_cast<std::size_t>(term[0]) * 3 * w;
        const double* m = cr + static_cast<std::size_t>(term[1]) * 3 * w;
        acc += load_lanes<W>(a) * load_lanes<W>(m) + load_lanes<W>(a + w) * load_lanes<W>(m + w) +
               load_lanes<W>(a + 2 * w) * load_lanes<W>(m + 2 * w);
      }
      store(k, acc);
    }
  } else if (dim_ == 2) {
    const double* d0 = deriv[0];
    const double* d1 = deriv[1];
    const V n0 = load_lanes<W>(refs), n1 = load_lanes<W>(refs + w), n2 = load_lanes<W>(refs + 2 * w);
    for (std::size_t k = 0; k < S; ++k) {
      V acc{};
      for (int t = cross_gather_.first[k]; t < cross_gather_.first[k + 1]; ++t) {
        const auto& term = cross_gather_.terms[static_cast<std::size_t>(t)];
        const double* a = d0 + static_cast<std::size_t>(term[0]) * 3 * w;
        const double* b = d1 + static_cast<std::size_t>(term[1]) * 3 * w;
        const V a0 = load_lanes<W>(a), a1 = load_lanes<W>(a + w);
        const V b0 = load_lanes<W>(b), b1 = load_lanes<W>(b + w);
        if (planar) {
          acc += a0 * b1 - a1 * b0;
        } else {
          const V a2 = load_lanes<W>(a + 2 * w), b2 = load_lanes<W>(b + 2 * w);
          acc += n0 * (a1 * b2 - a2 * b1) + n1 * (a2 * b0 - a0 * b2) + n2 * (a0 * b1 - a1 * b0);
        }
      }
      store(k, acc);
    }
  } else {
    const double* d0 = deriv[0];
    const V n0 = load_lanes<W>(refs), n1 = load_lanes<W>(refs + w), n2 = load_lanes<W>(refs + 2 * w);
    for (std::size_t k = 0; k < S; ++k) {
      const double* a = d0 + k * 3 * w;
      store(k, n0 * load_lanes<W>(a) + n1 * load_lanes<W>(a + w) + n2 * load_lanes<W>(a + 2 * w));
    }
  }

  // Error bounds (model at the top of this file), all lanes at once: each lane performs
  // the operations, in the order, of an element alone.
  const double eps_d = 4 * kUnit + rounding_gamma(static_cast<int>(n));
  static constexpr int kPerm[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {1, 0, 2}, {2, 1, 0}};
  V hat[3][3] = {}, delta[3][3] = {};
  for (int c = 0; c < dim_; ++c)
    for (std::size_t j = 0; j < 3; ++j) {
      const auto cs = static_cast<std::size_t>(c);
      delta[c][j] = eps_d * map.row_sum[cs] * load_lanes<W>(range + j * w) * (1 + 1e-10);
      hat[c][j] = load_lanes<W>(big[c][j]) * (1 + 4 * kUnit) + delta[c][j];
    }
  V pert{}, mag{};
  if (dim_ == 3) {
    for (const auto& pm : kPerm) {
      const V a = hat[0][pm[0]], b = hat[1][pm[1]], c = hat[2][pm[2]];
      pert += delta[0][pm[0]] * b * c + a * delta[1][pm[1]] * c + a * b * delta[2][pm[2]];
      mag += a * b * c;
    }
  } else {
    double abs_refs[3][W];
    for (std::size_t j = 0; j < 3; ++j)
      for (std::size_t l = 0; l < w; ++l) abs_refs[j][l] = std::abs(refs[j * w + l]);
    if (dim_ == 2) {
      for (const auto& pm : kPerm) {
        const V r = load_lanes<W>(abs_refs[pm[0]]);
        const V a = hat[0][pm[1]], b = hat[1][pm[2]];
        pert += r * (delta[0][pm[1]] * b + a * delta[1][pm[2]]);
        mag += r * a * b;
      }
    } else {
      for (std::size_t j = 0; j < 3; ++j) {
        const V r = load_lanes<W>(abs_refs[j]);
        pert += r * delta[0][j];
        mag += r * hat[0][j];
      }
    }
  }
  const V err = (pert + rounding_ * mag) * 1.01;
  std::memcpy(errors, &err, sizeof err);
}

void JacobianProduct::coefficients(SampleMap which, const double* nodes, std::size_t count,
                                   bool planar, double* coeffs, double* errors,
                                   ProductScratch& sc) const {
  const Map& map = maps_[static_cast<std::size_t>(which)];
  const std::size_t stride = static_cast<std::size_t>(type_->num_nodes) * 3;
  const auto S = static_cast<std::size_t>(basis_->size());
  constexpr auto lanes = static_cast<std::size_t>(kLanes);
  sc.block.resize(block_size(map, kLanes));
  std::size_t e = 0;
  for (; e + lanes <= count; e += lanes)
    lane_block<kLanes>(map, nodes + e * stride, stride, planar, coeffs + e * S, errors + e, sc.block.data());
  // The rest one by one, each in two lanes (stride 0; lane_vector.hpp on one-lane vectors).
  sc.pair.resize(2 * S);
  for (; e < count; ++e) {
    double err[2];
    lane_block<2>(map, nodes + e * stride, 0, planar, sc.pair.data(), err, sc.block.data());
    std::copy_n(sc.pair.data(), S, coeffs + e * S);
    errors[e] = err[0];
  }
}

std::vector<mpq_class> JacobianProduct::exact_coefficients(SampleMap which, const double* nodes,
                                                           bool planar) const {
  build_exact();
  const Map& map = maps_[static_cast<std::size_t>(which)];
  const auto n = static_cast<std::size_t>(map.num_nodes);
  const auto lat = static_cast<std::size_t>(lattice_.total);
  const auto S = static_cast<std::size_t>(basis_->size());
  // Exact derivative coefficients per direction and coordinate (scaled).
  std::array<std::array<std::vector<mpq_class>, 3>, 3> d;
  for (std::size_t j = 0; j < 3; ++j) {
    if (map.pyramid) {  // monomial coefficients of coordinate j, then the derivatives
      const auto& py = *map.pyramid;
      std::vector<mpq_class> mono(n, mpq_class(0));
      for (std::size_t m = 0; m < n; ++m)
        for (std::size_t i = 0; i < n; ++i)
          if (sgn(py.coefficients[m * n + i]) != 0) mono[m] += py.coefficients[m * n + i] * mpq_class(nodes[3 * i + j]);
      for (int c = 0; c < dim_; ++c) d[static_cast<std::size_t>(c)][j] = pyramid_scaled_derivative(order_, c, py.exponents, mono);
      continue;
    }
    std::vector<mpq_class> values(lat, mpq_class(0));
    if (map.to_lattice.empty()) {
      for (std::size_t i = 0; i < n; ++i) values[static_cast<std::size_t>(lattice_of_node_[i])] = nodes[3 * i + j];
    } else {
      for (std::size_t l = 0; l < lat; ++l)
        for (std::size_t i = 0; i < n; ++i)
          if (sgn(map.to_lattice[l * n + i]) != 0) values[l] += map.to_lattice[l * n + i] * mpq_class(nodes[3 * i + j]);
    }
    for (int c = 0; c < dim_; ++c) d[static_cast<std::size_t>(c)][j] = exact_derivative(c, values);
  }
  std::vector<mpq_class> out(S, mpq_class(0));
  const auto r = reference_direction(*type_, nodes, planar);
  if (dim_ == 3) {
    const auto kc = static_cast<std::size_t>(cross_size_);
    std::array<std::vector<mpq_class>, 3> cr;
    for (auto& v : cr) v.assign(kc, mpq_class(0));
    for_each_term(cross_gather_, [&](int ib, int ic, int im) {
      const auto b = static_cast<std::size_t>(ib), c = static_cast<std::size_t>(ic), m = static_cast<std::size_t>(im);
      cr[0][m] += d[1][1][b] * d[2][2][c] - d[1][2][b] * d[2][1][c];
      cr[1][m] += d[1][2][b] * d[2][0][c] - d[1][0][b] * d[2][2][c];
      cr[2][m] += d[1][0][b] * d[2][1][c] - d[1][1][b] * d[2][0][c];
    });
    for_each_term(dot_gather_, [&](int ia, int im, int ik) {
      const auto a = static_cast<std::size_t>(ia), m = static_cast<std::size_t>(im);
      out[static_cast<std::size_t>(ik)] += d[0][0][a] * cr[0][m] + d[0][1][a] * cr[1][m] + d[0][2][a] * cr[2][m];
    });
  } else if (dim_ == 2) {
    const mpq_class n0(r[0]), n1(r[1]), n2(r[2]);
    const mpq_class nz = planar ? mpq_class(1) : n2;
    for_each_term(cross_gather_, [&](int ia, int ib, int ik) {
      const auto a = static_cast<std::size_t>(ia), b = static_cast<std::size_t>(ib);
      mpq_class v = nz * (d[0][0][a] * d[1][1][b] - d[0][1][a] * d[1][0][b]);
      if (!planar)
        v += n0 * (d[0][1][a] * d[1][2][b] - d[0][2][a] * d[1][1][b]) +
             n1 * (d[0][2][a] * d[1][0][b] - d[0][0][a] * d[1][2][b]);
      out[static_cast<std::size_t>(ik)] += v;
    });
  } else {
    for (std::size_t k = 0; k < S; ++k)
      out[k] = mpq_class(r[0]) * d[0][0][k] + mpq_class(r[1]) * d[0][1][k] + mpq_class(r[2]) * d[0][2][k];
  }
  for (std::size_t k = 0; k < S; ++k) out[k] /= mult_[k];
  return out;
}

}  // namespace quadval
