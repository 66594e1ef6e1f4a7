// A certified upper bound of sj(E) from a local search (scaled_jacobian_probe.hpp).
#include "analysis/scaled_jacobian_probe.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <utility>
#include <vector>

#include "analysis/outward_rounding.hpp"
#include "analysis/sqrt_rn.hpp"
#include "quadval/bezier_basis.hpp"
#include "quadval/error.hpp"

namespace quadval {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kFinestStep = 12;  // coordinates stay multiples of 2^-12: 1 - sum is exact
constexpr int kMaxEvaluations = 400;
double up(double x) { return next_up(x); }

// One simplex factor's basis in a form cheap to evaluate: per coefficient its exponents
// (alpha_0 .. alpha_d) and multinomial n! / prod alpha!. Shared per (dim, degree), as
// bernstein_simplex is: a probe is built per element, its tables only once.
struct FactorTable {
  int dim = 0, degree = 0, size = 0;
  std::vector<std::uint8_t> exponents;  // size x (dim + 1)
  std::vector<double> multinomial;
};

FactorTable build_factor_table(int dim, int degree) {
  const BernsteinSimplex& b = bernstein_simplex(dim, degree);
  QV_ASSERT(degree < 32, "degree " << degree);
  FactorTable t{dim, degree, b.size(), {}, {}};
  for (const auto& alpha : b.multi_indices()) {
    // n! / prod alpha_a!, built as a product of binomials: exact integers far below 2^53.
    std::uint64_t v = 1;
    int taken = 0;
    for (int a = 0; a <= dim; ++a) {
      t.exponents.push_back(static_cast<std::uint8_t>(alpha[static_cast<std::size_t>(a)]));
      for (int k = 1; k <= alpha[static_cast<std::size_t>(a)]; ++k) v = v * static_cast<std::uint64_t>(++taken) / static_cast<std::uint64_t>(k);
    }
    t.multinomial.push_back(static_cast<double>(v));
  }
  return t;
}

const FactorTable& factor_table(int dim, int degree) {
  static std::mutex mutex;
  static std::map<std::pair<int, int>, std::unique_ptr<const FactorTable>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[{dim, degree}];
  if (!slot) slot = std::make_unique<const FactorTable>(build_factor_table(dim, degree));
  return *slot;
}

// One tensor space (J's or a column's): its factors, first varying fastest.
struct Space {
  std::array<const FactorTable*, 3> factors{};
  int num_factors = 0;
  int size = 1;
  int largest_factor = 0;
  int roundings = 0;  // of one basis value: sum over factors of n + d + 1, plus the tensor's
};

Space make_space(const std::vector<FactorDegree>& degrees) {
  Space s;
  QV_ASSERT(degrees.size() <= 3, degrees.size() << " factors");
  for (const FactorDegree& fd : degrees) {
    const FactorTable& t = factor_table(fd.dim, fd.degree);
    s.factors[static_cast<std::size_t>(s.num_factors++)] = &t;
    s.size *= t.size;
    s.largest_factor = std::max(s.largest_factor, t.size);
    s.roundings += fd.degree + fd.dim + 1;
  }
  s.roundings += s.num_factors - 1;
  return s;
}

// The tensor basis values at point x (the factors' local coordinates, concatenated) into
// out[0 .. s.size); factor_values holds at least s.largest_factor values.
void basis_at(const Space& s, const double* x, double* out, double* factor_values) {
  out[0] = 1.0;
  std::size_t inner = 1;
  int at = 0;
  for (int f = 0; f < s.num_factors; ++f) {
    const FactorTable& t = *s.factors[static_cast<std::size_t>(f)];
    const int d = t.dim, n = t.degree;
    std::array<double, 4> lambda{1, 0, 0, 0};
    for (int c = 0; c < d; ++c) {
      lambda[static_cast<std::size_t>(c + 1)] = x[at + c];
      lambda[0] -= x[at + c];  // exact: dyadic coordinates of at most 12 bits
    }
    at += d;
    std::array<std::array<double, 32>, 4> power;  // rows 0..d, entries 0..n set below
    for (int a = 0; a <= d; ++a) {
      double* p = power[static_cast<std::size_t>(a)].data();
      p[0] = 1;
      for (int k = 1; k <= n; ++k) p[k] = p[k - 1] * lambda[static_cast<std::size_t>(a)];
    }
    const std::uint8_t* e = t.exponents.data();
    for (int i = 0; i < t.size; ++i, e += d + 1) {
      double v = t.multinomial[static_cast<std::size_t>(i)];
      for (int a = 0; a <= d; ++a) v *= power[static_cast<std::size_t>(a)][e[a]];
      factor_values[i] = v;
    }
    // Factor f varies slowest so far: out (earlier factors) fastest, as the coefficients.
    for (std::size_t i = static_cast<std::size_t>(t.size); i-- > 0;)
      for (std::size_t k = 0; k < inner; ++k) out[i * inner + k] = out[k] * factor_values[i];
    inner *= static_cast<std::size_t>(t.size);
  }
}

double dot(std::span<const double> c, const double* basis) {
  double sum = 0;
  for (std::size_t i = 0; i < c.size(); ++i) sum += c[i] * basis[i];
  return sum;
}

// The points of the degree-4 lattice of every factor, as a tensor product.
std::vector<std::array<double, 3>> start_points(const std::vector<int>& dims) {
  std::vector<std::array<double, 3>> points{{0, 0, 0}};
  std::size_t at = 0;
  for (int d : dims) {
    std::vector<std::array<double, 3>> next;
    const BernsteinSimplex& lattice = bernstein_simplex(d, 4);
    for (const auto& p : points)
      for (const auto& alpha : lattice.multi_indices()) {
        std::array<double, 3> q = p;
        for (int c = 0; c < d; ++c) q[at + static_cast<std::size_t>(c)] = alpha[static_cast<std::size_t>(c + 1)] / 4.0;
        next.push_back(q);
      }
    points = std::move(next);
    at += static_cast<std::size_t>(d);
  }
  return points;
}


// The basis values of J's space and of the columns' at the start points, which are the same
// for every element of one space: the start (most of a triangle's evaluations) is then
// dot products only, with the same values basis_at gives there.
struct Lattice {
  std::vector<std::array<double, 3>> points;
  std::vector<double> j;                   // point p's values at p * j_size
  std::array<std::vector<double>, 3> col;  // likewise per column
};

const Lattice& lattice_of(const Space& j_space, const std::array<Space, 3>& col_space, std::size_t columns,
                          const std::vector<int>& factor_dims) {
  static std::mutex mutex;
  static std::map<std::vector<int>, std::unique_ptr<const Lattice>> cache;
  std::vector<int> key;
  for (std::size_t c = 0; c <= columns; ++c) {
    const Space& sp = c == 0 ? j_space : col_space[c - 1];
    for (int f = 0; f < sp.num_factors; ++f)
      key.insert(key.end(), {sp.factors[static_cast<std::size_t>(f)]->dim, sp.factors[static_cast<std::size_t>(f)]->degree});
    key.push_back(-1);
  }
  const std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[key];
  if (!slot) {
    auto l = std::make_unique<Lattice>();
    l->points = start_points(factor_dims);
    int largest = 0;
    for (std::size_t c = 0; c <= columns; ++c)
      for (int f = 0; f < (c == 0 ? j_space : col_space[c - 1]).num_factors; ++f)
        largest = std::max(largest, (c == 0 ? j_space : col_space[c - 1]).factors[static_cast<std::size_t>(f)]->size);
    std::vector<double> factor_values(static_cast<std::size_t>(largest));
    const auto fill = [&](const Space& sp, std::vector<double>& out) {
      out.resize(l->points.size() * static_cast<std::size_t>(sp.size));
      for (std::size_t p = 0; p < l->points.size(); ++p)
        basis_at(sp, l->points[p].data(), out.data() + p * static_cast<std::size_t>(sp.size), factor_values.data());
    };
    fill(j_space, l->j);
    for (std::size_t c = 0; c < columns; ++c) fill(col_space[c], l->col[c]);
    slot = std::move(l);
  }
  return *slot;
}

class Probe {
 public:
  Probe(const ScaledJacobianSpace& space, const QuotientInput& in) : space_(space), in_(in) {
    dim_ = static_cast<std::size_t>(space.dim());
    j_space_ = make_space(*in.j_degrees);
    for (std::size_t c = 0; c < dim_; ++c) col_space_[c] = make_space(*in.col_degrees[c]);
    for (const FactorDegree& fd : *in.j_degrees) factor_dims_.push_back(fd.dim);
    int size = j_space_.size, factor = j_space_.largest_factor;
    for (std::size_t c = 0; c < dim_; ++c) {
      size = std::max(size, col_space_[c].size);
      factor = std::max(factor, col_space_[c].largest_factor);
    }
    basis_.resize(static_cast<std::size_t>(size));
    factor_values_.resize(static_cast<std::size_t>(factor));
    lattice_ = &lattice_of(j_space_, col_space_, dim_, factor_dims_);
  }

  // The start points, and the estimate at start point p (as estimate at that point).
  const std::vector<std::array<double, 3>>& start() const { return lattice_->points; }
  double estimate_start(std::size_t p) {
    j_ = dot(in_.j, lattice_->j.data() + p * static_cast<std::size_t>(j_space_.size));
    for (std::size_t c = 0; c < dim_; ++c) {
      const double* basis = lattice_->col[c].data() + p * static_cast<std::size_t>(col_space_[c].size);
      for (std::size_t k = 0; k < 3; ++k) col_[c][k] = dot(in_.col[c][k], basis);
    }
    return objective();
  }

  // sj / s at x in floating point (the search's objective); +inf where no frame has
  // nonzero column norms.
  double estimate(const double* x) {
    evaluate(x);
    return objective();
  }

  // A certified upper bound of sj(E) at x, or 0 where J < 0 is not certain there.
  double certified(const double* x) {
    evaluate(x);
    const double j_error = up(in_.j_error + up(rounding_gamma(static_cast<int>(in_.j.size()) + j_space_.roundings + 2) *
                                               largest(in_.j) * 1.01));
    const double j_hi = up(j_ + j_error);
    if (!(j_hi < 0)) return 0;
    std::array<double, 3> col_error{};
    for (std::size_t c = 0; c < dim_; ++c)
      col_error[c] = up(in_.col_error[c] + up(rounding_gamma(col_size(c) + col_space_[c].roundings + 2) *
                                                in_.col_magnitude[c] * 1.01));
    double upper = 0;
    for (const Frame& fr : space_.frames()) {
      double bound = 1;
      for (std::size_t j = 0; j < dim_; ++j) {
        // Coordinate error: its columns' errors plus the rounding of their signed sum.
        double e = 0, magnitude = 0;
        for (std::size_t c = 0; c < dim_; ++c)
          if (fr[j][c] != 0) {
            e += col_error[c];
            magnitude += in_.col_magnitude[c];
          }
        e = up(up(e + rounding_gamma(3) * magnitude) * 1.01);
        bound = up(bound * up(up(frame_norm(fr, j) * (1 + 1e-12)) + up(up(1.7320508075688772) * e)));
      }
      if (!(bound > 0)) continue;  // (a vanishing column means J = 0 there: not reached)
      upper = std::min(upper, up(space_.s_lo() * up(j_hi / bound)));
    }
    return upper;
  }

  // Local coordinates x (3 at most) inside the reference domain, every factor's simplex.
  bool inside(const double* x) const {
    std::size_t at = 0;
    for (int d : factor_dims_) {
      double sum = 0;
      for (int c = 0; c < d; ++c) {
        if (x[at + static_cast<std::size_t>(c)] < 0) return false;
        sum += x[at + static_cast<std::size_t>(c)];
      }
      if (sum > 1) return false;
      at += static_cast<std::size_t>(d);
    }
    return true;
  }
  const std::vector<int>& factor_dims() const { return factor_dims_; }

 private:
  static double largest(std::span<const double> c) {
    double m = 0;
    for (double v : c) m = std::max(m, std::abs(v));
    return m;
  }
  int col_size(std::size_t c) const { return static_cast<int>(in_.col[c][0].size()); }
  // The estimate from the values at the last point evaluated.
  double objective() const {
    double best = kInf;
    for (const Frame& fr : space_.frames()) {
      double norms = 1;
      for (std::size_t j = 0; j < dim_; ++j) norms *= frame_norm(fr, j);
      if (norms > 0) best = std::min(best, j_ / norms);
    }
    return best;
  }
  // |frame column j| from the columns' values at the last evaluated point.
  double frame_norm(const Frame& fr, std::size_t j) const {
    double sum = 0;
    for (std::size_t x = 0; x < 3; ++x) {
      double v = 0;
      for (std::size_t c = 0; c < dim_; ++c)
        if (fr[j][c] != 0) v += fr[j][c] * col_[c][x];
      sum += v * v;
    }
    return sqrt_rn(sum);
  }
  void evaluate(const double* x) {
    basis_at(j_space_, x, basis_.data(), factor_values_.data());
    j_ = dot(in_.j, basis_.data());
    for (std::size_t c = 0; c < dim_; ++c) {
      basis_at(col_space_[c], x, basis_.data(), factor_values_.data());
      for (std::size_t k = 0; k < 3; ++k) col_[c][k] = dot(in_.col[c][k], basis_.data());
    }
  }

  const ScaledJacobianSpace& space_;
  const QuotientInput& in_;
  std::size_t dim_ = 0;
  Space j_space_;
  std::array<Space, 3> col_space_;
  std::vector<int> factor_dims_;
  std::vector<double> basis_, factor_values_;
  const Lattice* lattice_ = nullptr;
  double j_ = 0;
  std::array<std::array<double, 3>, 3> col_{};
};

}  // namespace

SjProbe probe_scaled_jacobian(const ScaledJacobianSpace& space, const QuotientInput& in, double enough) {
  Probe probe(space, in);
  const double target = enough / space.s_hi();  // in the estimates' units, sj / s
  int evaluations = 0;
  std::array<double, 3> best{};
  double best_value = kInf;
  for (std::size_t p = 0; p < probe.start().size(); ++p) {
    const double v = probe.estimate_start(p);
    ++evaluations;
    if (v < best_value) {
      best_value = v;
      best = probe.start()[p];
    }
  }
  if (!(best_value < 0)) return {0, best};
  if (best_value <= target) return {probe.certified(best.data()), best};
  // Compass search: along each coordinate, and along the edges of each simplex factor of
  // dimension 2 or 3 (a coordinate traded for another), the best improving move at step
  // h, else h halves.
  std::vector<std::array<double, 3>> directions;
  std::size_t at = 0;
  for (int d : probe.factor_dims()) {
    for (int a = 0; a < d; ++a) {
      std::array<double, 3> e{};
      e[at + static_cast<std::size_t>(a)] = 1;
      directions.push_back(e);
      for (int b = a + 1; b < d; ++b) {
        std::array<double, 3> t{};
        t[at + static_cast<std::size_t>(a)] = 1;
        t[at + static_cast<std::size_t>(b)] = -1;
        directions.push_back(t);
      }
    }
    at += static_cast<std::size_t>(d);
  }
  for (int step = 3; step <= kFinestStep && evaluations < kMaxEvaluations && best_value > target;) {
    const double h = std::ldexp(1.0, -step);
    std::array<double, 3> move = best;
    double move_value = best_value;
    for (const auto& dir : directions)
      for (const double sign : {1.0, -1.0}) {
        std::array<double, 3> q = best;
        for (std::size_t c = 0; c < 3; ++c) q[c] += sign * h * dir[c];
        if (!probe.inside(q.data())) continue;
        const double v = probe.estimate(q.data());
        ++evaluations;
        if (v < move_value) {
          move_value = v;
          move = q;
        }
      }
    if (move_value < best_value) {
      best = move;
      best_value = move_value;
    } else {
      ++step;
    }
  }
  return {probe.certified(best.data()), best};
}

}  // namespace quadval
