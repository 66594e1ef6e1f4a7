#pragma once
// Helpers shared by the Jacobian-bounds tests: random curved elements, and J evaluated
// straight from the Lagrange shape-function gradients (lagrange_basis.hpp), which shares
// no code with the Bézier pipeline under test.
#include <array>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <cmath>
#include <random>
#include <vector>

#include "quadval/bezier_basis.hpp"
#include "quadval/element_type.hpp"
#include "quadval/lagrange_basis.hpp"
#include "quadval/mesh.hpp"

namespace quadval::test {

/// An element of `type`: its reference nodes through a random well-conditioned affine map,
/// then every node moved by up to `amplitude` (relative to the element size ~1) at random.
/// 2D elements lie in the plane z = 0 (planar), 1D on a random 3D segment.
inline std::vector<double> random_element(const ElementType& type, double amplitude,
                                          std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  const auto ref = reference_nodes(type);
  const int dim = type.dim;
  double a[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) a[i][j] += 0.2 * u(rng);
  if (dim == 2) a[2][0] = a[2][1] = a[0][2] = a[1][2] = 0, a[2][2] = 1;
  std::vector<double> x;
  const double shift[3] = {10 * u(rng), 10 * u(rng), dim == 2 ? 0.0 : 10 * u(rng)};
  for (const auto& p : ref) {
    for (int i = 0; i < 3; ++i) {
      double v = shift[i];
      for (int j = 0; j < 3; ++j) v += a[i][j] * p[static_cast<std::size_t>(j)];
      if (dim == 1 && i > 0) v = shift[i] + 0.3 * (i) * p[0];
      if (!(dim == 2 && i == 2)) v += amplitude * u(rng);
      x.push_back(v);
    }
  }
  return x;
}

/// An element of `type` curved the way a mesher curves one: random_element's random affine
/// map (without its node noise), then a smooth displacement x_c += amplitude sin(k_c . xi +
/// phase_c) per coordinate c (2D: x and y), xi the reference node, k_c in [-2, 2]^3. At high
/// orders such elements stay valid for small amplitudes where independent noise at each node
/// does not: the equispaced interpolant amplifies it (at order 10 every such element was
/// invalid).
inline std::vector<double> smooth_random_element(const ElementType& type, double amplitude,
                                                 std::mt19937& rng) {
  std::uniform_real_distribution<double> w(-2, 2), phase(0, 6.283);
  std::vector<double> x = random_element(type, 0.0, rng);
  double k[3][3], ph[3];
  for (int c = 0; c < 3; ++c) {
    for (double& v : k[c]) v = w(rng);
    ph[c] = phase(rng);
  }
  const auto ref = reference_nodes(type);
  for (std::size_t i = 0; i < ref.size(); ++i)
    for (int c = 0; c < (type.dim == 2 ? 2 : 3); ++c)
      x[3 * i + static_cast<std::size_t>(c)] +=
          amplitude * std::sin(k[c][0] * ref[i][0] + k[c][1] * ref[i][1] + k[c][2] * ref[i][2] + ph[c]);
  return x;
}

/// J at a reference point (Gmsh coordinates), from the shape-function gradients; the 1D
/// and 2D conventions of jacobian_bounds.hpp (planar 2D: n = +z).
inline double jacobian_at(const LagrangeBasis& basis, const std::vector<double>& x,
                          const RefPoint& p, bool planar) {
  const int n = basis.num_nodes();
  std::vector<double> g(static_cast<std::size_t>(3 * n));
  basis.evaluate_gradients(p, g);
  double d[3][3] = {};
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c)
      for (int j = 0; j < 3; ++j) d[c][j] += g[static_cast<std::size_t>(3 * i + c)] * x[static_cast<std::size_t>(3 * i + j)];
  const int dim = basis.type().dim;
  const auto cross = [](const double* a, const double* b, double* c) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
  };
  if (dim == 3) {
    double c[3];
    cross(d[1], d[2], c);
    return d[0][0] * c[0] + d[0][1] * c[1] + d[0][2] * c[2];
  }
  if (dim == 2) {
    double nrm[3] = {0, 0, 1};
    if (!planar) {
      const bool quad = basis.type().family == ElementFamily::quadrangle;
      double e1[3], e2[3];
      for (int j = 0; j < 3; ++j) {
        e1[j] = quad ? x[static_cast<std::size_t>(6 + j)] - x[static_cast<std::size_t>(j)] : x[static_cast<std::size_t>(3 + j)] - x[static_cast<std::size_t>(j)];
        e2[j] = quad ? x[static_cast<std::size_t>(9 + j)] - x[static_cast<std::size_t>(3 + j)] : x[static_cast<std::size_t>(6 + j)] - x[static_cast<std::size_t>(j)];
      }
      cross(e1, e2, nrm);
      const double l = std::sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
      for (double& v : nrm) v /= l;
    }
    double c[3];
    cross(d[0], d[1], c);
    return nrm[0] * c[0] + nrm[1] * c[1] + nrm[2] * c[2];
  }
  double t[3];
  for (int j = 0; j < 3; ++j) t[j] = x[static_cast<std::size_t>(3 + j)] - x[static_cast<std::size_t>(j)];
  const double l = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
  return (d[0][0] * t[0] + d[0][1] * t[1] + d[0][2] * t[2]) / l;
}

/// Points of the Gmsh reference domain of a family: a lattice of `m` steps per direction
/// (inside the element), plus `random_count` random points.
inline std::vector<RefPoint> dense_points(ElementFamily f, int m, int random_count,
                                          std::mt19937& rng) {
  std::vector<RefPoint> pts;
  std::uniform_real_distribution<double> u(0, 1);
  const auto add_unit = [&](double a, double b, double c) {
    // a, b, c in the Bézier domain; map to Gmsh's
    switch (f) {
      case ElementFamily::line: pts.push_back({2 * a - 1, 0, 0}); break;
      case ElementFamily::triangle: if (a + b <= 1) pts.push_back({a, b, 0}); break;
      case ElementFamily::quadrangle: pts.push_back({2 * a - 1, 2 * b - 1, 0}); break;
      case ElementFamily::tetrahedron: if (a + b + c <= 1) pts.push_back({a, b, c}); break;
      case ElementFamily::prism: if (a + b <= 1) pts.push_back({a, b, 2 * c - 1}); break;
      case ElementFamily::hexahedron: pts.push_back({2 * a - 1, 2 * b - 1, 2 * c - 1}); break;
      case ElementFamily::pyramid:  // cube coordinates (a, b, t = 1 - c); never the apex
        if (c < 1) pts.push_back({(2 * a - 1) * (1 - c), (2 * b - 1) * (1 - c), c});
        break;
      default: break;
    }
  };
  const int dim = family_dimension(f);
  for (int i = 0; i <= m; ++i)
    for (int j = 0; j <= (dim >= 2 ? m : 0); ++j)
      for (int k = 0; k <= (dim >= 3 ? m : 0); ++k) add_unit(double(i) / m, double(j) / m, double(k) / m);
  for (int r = 0; r < random_count; ++r) add_unit(u(rng), u(rng), u(rng));
  return pts;
}

/// Every Lagrange type whose Jacobian bounds are computed, up to order max_order.
inline std::vector<const ElementType*> analysed_types(int max_order_2d, int max_order_3d) {
  std::vector<const ElementType*> out;
  for (const ElementType& t : element_types()) {
    if (!t.has_lagrange_basis || t.order < 1 || t.order > max_supported_order(t.family)) continue;
    switch (t.family) {
      case ElementFamily::line:
      case ElementFamily::triangle:
      case ElementFamily::quadrangle:
        if (t.order <= max_order_2d) out.push_back(&t);
        break;
      case ElementFamily::tetrahedron:
      case ElementFamily::prism:
      case ElementFamily::hexahedron:
        if (t.order <= max_order_3d) out.push_back(&t);
        break;
      default: break;
    }
  }
  return out;
}

/// Gmsh's minJ/maxJ per element tag from a shared-data NAME.gmsh.csv (column 5; <= 0 means
/// Gmsh calls the element invalid).
inline std::map<Tag, double> read_gmsh_ratios(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // header
  std::map<Tag, double> out;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string cell[5];
    for (auto& c : cell) std::getline(ss, c, ',');
    out[std::stoull(cell[0])] = std::stod(cell[4]);
  }
  return out;
}

/// The coordinates of element e of block b (#nodes x 3, Gmsh order).
inline std::vector<double> element_coordinates(const Mesh& mesh, const ElementBlock& b, std::size_t e) {
  std::vector<double> x;
  for (NodeIndex n : b.element(e))
    for (std::size_t j = 0; j < 3; ++j) x.push_back(mesh.coords[3 * static_cast<std::size_t>(n) + j]);
  return x;
}

/// A mesh of one block holding these elements (#nodes x 3 coordinates each, Gmsh order),
/// each with its own nodes; tags 1, 2, ... in order.
inline Mesh mesh_of_elements(const ElementType& type, const std::vector<std::vector<double>>& elements) {
  Mesh mesh;
  ElementBlock blk;
  blk.type = &type;
  blk.entity_dim = type.dim;
  blk.entity_tag = 1;
  for (const std::vector<double>& x : elements) {
    blk.tags.push_back(blk.tags.size() + 1);
    for (std::size_t v = 0; v < x.size() / 3; ++v) {
      blk.nodes.push_back(static_cast<NodeIndex>(mesh.node_tags.size()));
      mesh.node_tags.push_back(mesh.node_tags.size() + 1);
      mesh.coords.insert(mesh.coords.end(), {x[3 * v], x[3 * v + 1], x[3 * v + 2]});
    }
  }
  mesh.blocks.push_back(std::move(blk));
  return mesh;
}

}  // namespace quadval::test
