#pragma once
// Small triangle meshes for the recombination tests, made in the test (no code under test).

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "quadval/element_type.hpp"
#include "quadval/mesh.hpp"

namespace quadval::test {

/// A triangle mesh: one block of Triangle 3 on entity (2, 1), tags 1..n, on the nodes `xyz`.
inline Mesh make_triangle_mesh_3d(const std::vector<std::array<double, 3>>& xyz,
                                  const std::vector<std::array<NodeIndex, 3>>& tris) {
  Mesh m;
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    m.node_tags.push_back(i + 1);
    m.coords.insert(m.coords.end(), xyz[i].begin(), xyz[i].end());
  }
  ElementBlock b;
  b.type = find_element_type(2);
  b.entity_dim = 2;
  b.entity_tag = 1;
  for (std::size_t t = 0; t < tris.size(); ++t) {
    b.tags.push_back(t + 1);
    b.nodes.insert(b.nodes.end(), tris[t].begin(), tris[t].end());
  }
  m.blocks.push_back(std::move(b));
  return m;
}

/// A planar triangle mesh (z = 0), as make_triangle_mesh_3d.
inline Mesh make_triangle_mesh(const std::vector<std::array<double, 2>>& xy,
                               const std::vector<std::array<NodeIndex, 3>>& tris) {
  std::vector<std::array<double, 3>> xyz;
  for (const auto& p : xy) xyz.push_back({p[0], p[1], 0.0});
  return make_triangle_mesh_3d(xyz, tris);
}

/// Jittered nx × ny grid on [0, nx] × [0, ny], each cell cut along a random diagonal
/// (counter-clockwise triangles); then `remove` random triangles are dropped and, if
/// `make_even`, one more when the count is odd. Boundary nodes are jittered along the
/// boundary only, so the domain stays the rectangle when remove == 0.
inline Mesh random_grid_mesh(int nx, int ny, unsigned seed, int remove = 0, bool make_even = true,
                             double jitter = 0.3) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-jitter, jitter);
  std::vector<std::array<double, 2>> xy;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      double x = i, y = j;
      if (i > 0 && i < nx) x += u(rng);
      if (j > 0 && j < ny) y += u(rng);
      xy.push_back({x, y});
    }
  auto id = [&](int i, int j) { return static_cast<NodeIndex>(j * (nx + 1) + i); };
  std::vector<std::array<NodeIndex, 3>> tris;
  std::bernoulli_distribution coin(0.5);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const NodeIndex a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if (coin(rng)) {
        tris.push_back({a, b, c});
        tris.push_back({a, c, d});
      } else {
        tris.push_back({a, b, d});
        tris.push_back({b, c, d});
      }
    }
  for (int k = 0; k < remove && tris.size() > 2; ++k)
    tris.erase(tris.begin() + static_cast<long>(rng() % tris.size()));
  if (make_even && tris.size() % 2 == 1) tris.erase(tris.begin() + static_cast<long>(rng() % tris.size()));
  return make_triangle_mesh(xy, tris);
}

}  // namespace quadval::test
