#pragma once
// Keeps the nodes of a recombined surface in 3D on the input surface. Smoothing moves a node
// in its tangent plane and a quad-vertex-merge puts it at the middle of a diagonal: on a
// curved surface both leave it (on a sphere of radius 1 meshed at h = 0.06: up to 3.6e-3
// inside, from the merges, and 6e-4 outside). Each such position is brought back to the
// nearest point of the input triangles, found by a walk from the triangle the node was last
// on, then lifted onto the smooth surface that Phong tessellation (Boubekeur and Alexa 2008)
// makes of the triangles and their vertex normals: the point is moved towards the tangent
// planes at the triangle's corners, weighted by its barycentric coordinates (alpha = 3/4).
// The vertex normals are per region, so a feature edge stays sharp.

#include <array>
#include <cstdint>
#include <vector>

#include "mixed_mesh.hpp"
#include "triangle_input.hpp"

namespace quadval::recombine_detail {

class SurfaceProjection {
 public:
  /// The triangles of `s` as they are now (the input surface, after any parity splits);
  /// its nodes start on them. Walks stay on the triangles of one region (feature edges
  /// bound the regions, feature_edges.hpp).
  explicit SurfaceProjection(const TriangleSurface& s);

  /// Makes room for nodes up to num_nodes (those added after construction have no triangle
  /// yet: they start from a neighbour's). Not thread-safe; call before parallel projections.
  void reserve_nodes(std::size_t num_nodes);

  /// The point of the input surface nearest to p, near where node v was last projected (or,
  /// for a node not yet placed, near node `near`); records the triangle found for v. Returns
  /// p itself when neither node has a triangle. Thread-safe for distinct v whose `near`
  /// nodes are not being projected at the same time.
  std::array<double, 3> project(NodeIndex v, const std::array<double, 3>& p, NodeIndex near);

  /// Whether node v has a triangle to start from (an input node, or one projected since).
  bool placed(NodeIndex v) const { return v < host_.size() && host_[v] != 0xffffffffu; }

 private:
  struct Nearest {
    std::array<double, 3> point;
    double distance2;
    int zeros;                 // barycentric coordinates at 0: 1 on an edge, 2 at a corner
    std::array<double, 3> bary;
  };
  Nearest nearest_on(std::uint32_t t, const std::array<double, 3>& p) const;
  std::array<double, 3> lifted(std::uint32_t t, const std::array<double, 3>& q, const std::array<double, 3>& b) const;

  std::vector<double> coords_;
  std::vector<std::array<NodeIndex, 3>> triangles_;
  std::vector<std::int32_t> region_;
  std::vector<std::array<std::uint32_t, 3>> neighbors_;      // across edge k = (k, k+1)
  std::vector<std::uint32_t> node_first_, node_triangles_;    // CSR: the triangles at a node
  std::vector<std::uint32_t> host_;                           // per node: its last triangle
  std::vector<std::array<double, 3>> corner_normal_;          // #triangles x 3, unit
};

}  // namespace quadval::recombine_detail
