// Lagrange shape functions: inverse of the generalized Vandermonde matrix of each type's
// space at its reference nodes, cached per type.
#include "quadval/lagrange_basis.hpp"

#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "polynomial_space.hpp"
#include "quadval/error.hpp"

namespace quadval {

namespace {

// Monomial spaces (incomplete simplices, prisms and pyramids of order >= 3: at most 78
// functions) are ill-conditioned: their Vandermonde matrix is inverted and evaluated in
// long double, which brings Triangle 30 / Tetrahedron 58 from ~2e-9 to ~1e-12.
constexpr int kMaxExtendedNodes = 128;

}  // namespace

struct LagrangeBasis::Impl {
  detail::PolynomialSpace space;
  detail::RowMajorMatrix coeffs;  ///< C(j, i): coefficient of phi_j in N_i
  bool extended = false;          ///< evaluate in long double with coeffs_long
  detail::RowMajorMatrixT<long double> coeffs_long;

  // values[i] (and gradients[3i+d] when G) at p in long double, rounded once at the end.
  template <bool G>
  void evaluate_extended(const RefPoint& p, std::span<double> out) const {
    const int n = static_cast<int>(space.exponents.size());
    std::array<long double, kMaxExtendedNodes> phi{};
    std::array<std::array<long double, 3>, kMaxExtendedNodes> dphi{};
    detail::for_each_basis_function<G, long double>(
        space, p, [&](int j, long double v, const std::array<long double, 3>& g) {
          phi[j] = v;
          dphi[j] = g;
        });
    for (int i = 0; i < n; ++i) {
      if constexpr (G) {
        long double acc[3] = {0, 0, 0};
        for (int j = 0; j < n; ++j)
          for (int d = 0; d < 3; ++d) acc[d] += dphi[j][d] * coeffs_long(j, i);
        for (int d = 0; d < 3; ++d) out[3 * i + d] = static_cast<double>(acc[d]);
      } else {
        long double acc = 0;
        for (int j = 0; j < n; ++j) acc += phi[j] * coeffs_long(j, i);
        out[i] = static_cast<double>(acc);
      }
    }
  }
};

LagrangeBasis::LagrangeBasis(const ElementType& type)
    : type_(&type), nodes_(reference_nodes(type)) {  // reference_nodes checks the type
  auto impl = std::make_unique<Impl>();
  impl->space = detail::polynomial_space(type);
  impl->extended = impl->space.factors == detail::FactorBasis::monomial && type.order >= 3;
  if (impl->extended) {
    QV_ASSERT(type.num_nodes <= kMaxExtendedNodes, type.name);
    impl->coeffs_long = detail::lagrange_coefficients_long(impl->space, nodes_);
    impl->coeffs = impl->coeffs_long.cast<double>();
  } else {
    impl->coeffs = detail::lagrange_coefficients(impl->space, nodes_);
  }
  impl_ = std::move(impl);
}

LagrangeBasis::~LagrangeBasis() = default;
LagrangeBasis::LagrangeBasis(LagrangeBasis&&) noexcept = default;
LagrangeBasis& LagrangeBasis::operator=(LagrangeBasis&&) noexcept = default;

void LagrangeBasis::evaluate(const RefPoint& p, std::span<double> values) const {
  const int n = num_nodes();
  QV_ASSERT(static_cast<int>(values.size()) >= n, values.size() << " < " << n);
  if (impl_->extended) return impl_->evaluate_extended<false>(p, values);
  Eigen::Map<Eigen::RowVectorXd> out(values.data(), n);
  out.setZero();
  const auto& c = impl_->coeffs;
  detail::for_each_basis_function<false>(impl_->space, p, [&](int j, double phi, const auto&) {
    out.noalias() += phi * c.row(j);
  });
}

void LagrangeBasis::evaluate_gradients(const RefPoint& p, std::span<double> gradients) const {
  const int n = num_nodes();
  QV_ASSERT(static_cast<int>(gradients.size()) >= 3 * n, gradients.size() << " < 3*" << n);
  if (impl_->extended) return impl_->evaluate_extended<true>(p, gradients);
  using Strided = Eigen::Map<Eigen::RowVectorXd, 0, Eigen::InnerStride<3>>;
  Strided g[3] = {Strided(gradients.data(), n), Strided(gradients.data() + 1, n),
                  Strided(gradients.data() + 2, n)};
  for (auto& gd : g) gd.setZero();
  const auto& c = impl_->coeffs;
  detail::for_each_basis_function<true>(
      impl_->space, p, [&](int j, double, const std::array<double, 3>& dphi) {
        for (int d = 0; d < 3; ++d)
          if (dphi[d] != 0.0) g[d].noalias() += dphi[d] * c.row(j);
      });
}

Eigen::MatrixXd LagrangeBasis::evaluate_batch(std::span<const RefPoint> points) const {
  const auto np = static_cast<Eigen::Index>(points.size());
  if (impl_->extended) {  // pointwise, to keep the long double accuracy
    detail::RowMajorMatrix out(np, num_nodes());
    for (Eigen::Index k = 0; k < np; ++k)
      evaluate(points[k], std::span<double>(out.row(k).data(), num_nodes()));
    return out;
  }
  detail::RowMajorMatrix phi(np, num_nodes());
  for (Eigen::Index k = 0; k < np; ++k)
    detail::for_each_basis_function<false>(impl_->space, points[k],
                                           [&](int j, double v, const auto&) { phi(k, j) = v; });
  return phi * impl_->coeffs;
}

std::array<Eigen::MatrixXd, 3> LagrangeBasis::evaluate_gradients_batch(
    std::span<const RefPoint> points) const {
  const auto np = static_cast<Eigen::Index>(points.size());
  if (impl_->extended) {  // pointwise, to keep the long double accuracy
    std::array<Eigen::MatrixXd, 3> out;
    for (auto& m : out) m.resize(np, num_nodes());
    std::vector<double> g(3 * num_nodes());
    for (Eigen::Index k = 0; k < np; ++k) {
      evaluate_gradients(points[k], g);
      for (int i = 0; i < num_nodes(); ++i)
        for (int d = 0; d < 3; ++d) out[d](k, i) = g[3 * i + d];
    }
    return out;
  }
  std::array<detail::RowMajorMatrix, 3> dphi;
  for (auto& m : dphi) m.resize(np, num_nodes());
  for (Eigen::Index k = 0; k < np; ++k)
    detail::for_each_basis_function<true>(
        impl_->space, points[k], [&](int j, double, const std::array<double, 3>& g) {
          for (int d = 0; d < 3; ++d) dphi[d](k, j) = g[d];
        });
  std::array<Eigen::MatrixXd, 3> out;
  for (int d = 0; d < 3; ++d) out[d] = dphi[d] * impl_->coeffs;
  return out;
}

const LagrangeBasis& lagrange_basis(const ElementType& type) {
  if (!type.has_lagrange_basis)
    throw std::invalid_argument("element type " + std::to_string(type.gmsh_id) + " (" +
                                std::string(type.name) + ") has no Lagrange basis");
  // One slot per Gmsh id (1..140), each built once under its own once_flag; the objects
  // are never destroyed before exit, so references stay valid.
  static std::array<std::once_flag, 141> once;
  static std::array<std::unique_ptr<const LagrangeBasis>, 141> cache;
  const ElementType* registered = find_element_type(type.gmsh_id);
  QV_ASSERT(registered && registered->has_lagrange_basis, "type " << type.gmsh_id);
  const int id = registered->gmsh_id;
  std::call_once(once[id], [&] { cache[id] = std::make_unique<LagrangeBasis>(*registered); });
  return *cache[id];
}

}  // namespace quadval
