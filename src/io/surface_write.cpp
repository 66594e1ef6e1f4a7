#include "io/surface_write.hpp"

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <fmt/core.h>

#include "io/out_buffer.hpp"
#include "quadval/element_type.hpp"
#include "quadval/error.hpp"

namespace quadval::io {

namespace {

constexpr std::uint32_t kUnused = 0xffffffffu;

// What both formats write: the face blocks (corner counts), and each used node's position
// in the vertex list.
struct Faces {
  std::vector<const ElementBlock*> blocks;
  std::vector<int> corners;            // per block: 3 or 4
  std::vector<std::uint32_t> vertex;   // per node: its 0-based vertex number, or kUnused
  std::vector<NodeIndex> used;         // the used nodes, ascending
  std::size_t count = 0;
};

// "N of type T (name), ..." for the counts per type id, and their total.
std::pair<std::size_t, std::string> listed(const std::map<int, std::size_t>& counts) {
  std::size_t total = 0;
  std::string list;
  for (const auto& [id, count] : counts) {
    total += count;
    list += fmt::format("{}{} of type {} ({})", list.empty() ? "" : ", ", count, id, find_element_type(id)->name);
  }
  return {total, list};
}

Faces collect_faces(const Mesh& mesh, const std::string& file) {
  QV_ASSERT(mesh.coords.size() == 3 * mesh.num_nodes(), "coordinates do not match the nodes");
  Faces f;
  f.vertex.assign(mesh.num_nodes(), kUnused);
  std::map<int, std::size_t> left_out, by_corners;  // per type id, for the warnings
  for (const ElementBlock& b : mesh.blocks) {
    if (b.size() == 0) continue;
    const ElementType& t = *b.type;
    if (t.dim == 3)
      throw InputError::in_file(file, fmt::format("OBJ and OFF hold surfaces, and this mesh has {} elements of "
                                                  "type {} ({}); write .msh or .vtu",
                                                  b.size(), t.gmsh_id, t.name));
    if (t.family != ElementFamily::triangle && t.family != ElementFamily::quadrangle) {
      left_out[t.gmsh_id] += b.size();
      continue;
    }
    const int corners = t.family == ElementFamily::triangle ? 3 : 4;
    if (t.num_nodes > corners) by_corners[t.gmsh_id] += b.size();
    f.blocks.push_back(&b);
    f.corners.push_back(corners);
    f.count += b.size();
    for (std::size_t e = 0; e < b.size(); ++e)
      for (int c = 0; c < corners; ++c) f.vertex[b.element(e)[static_cast<std::size_t>(c)]] = 0;
  }
  if (!left_out.empty()) {
    const auto [total, list] = listed(left_out);
    fmt::print(stderr, "quadval: warning: {}: {} point and line elements not written (OBJ and OFF hold faces only): {}\n",
               file, total, list);
  }
  if (!by_corners.empty()) {
    const auto [total, list] = listed(by_corners);
    fmt::print(stderr, "quadval: warning: {}: {} curved faces written with their corners only (OBJ and OFF faces "
                       "are straight): {}\n", file, total, list);
  }
  if (f.count == 0) throw InputError::in_file(file, "the mesh has no triangle or quadrangle to write as a face");
  for (NodeIndex v = 0; v < mesh.num_nodes(); ++v)
    if (f.vertex[v] != kUnused) {
      f.vertex[v] = static_cast<std::uint32_t>(f.used.size());
      f.used.push_back(v);
    }
  return f;
}

// The vertex lines: prefix, then x y z.
void write_vertices(OutBuffer& o, const Mesh& mesh, const Faces& f, const char* prefix) {
  o.records(f.used.size(), [&](OutBuffer& p, std::size_t i) {
    const double* x = mesh.coords.data() + 3 * std::size_t{f.used[i]};
    p.text(prefix);
    p.real(x[0]);
    p.put(' ');
    p.real(x[1]);
    p.put(' ');
    p.real(x[2]);
    p.put('\n');
  });
}

// The face lines: prefix, then the corners' vertex numbers plus `base`.
void write_faces(OutBuffer& o, const Faces& f, bool with_count, std::uint64_t base) {
  for (std::size_t k = 0; k < f.blocks.size(); ++k) {
    const ElementBlock& b = *f.blocks[k];
    const int corners = f.corners[k];
    o.records(b.size(), [&](OutBuffer& p, std::size_t e) {
      const auto nodes = b.element(e);
      if (with_count)
        p.integer(static_cast<std::uint64_t>(corners));
      else
        p.put('f');
      for (int c = 0; c < corners; ++c) {
        p.put(' ');
        p.integer(base + f.vertex[nodes[static_cast<std::size_t>(c)]]);
      }
      p.put('\n');
    });
  }
}

}  // namespace

void write_obj(const Mesh& mesh, std::ostream& out, const std::string& file) {
  const Faces f = collect_faces(mesh, file);
  OutBuffer o(out);
  o.text("# quadval: vertices {}, faces {}\n", f.used.size(), f.count);
  write_vertices(o, mesh, f, "v ");
  write_faces(o, f, false, 1);
  o.flush();
}

void write_off(const Mesh& mesh, std::ostream& out, const std::string& file) {
  const Faces f = collect_faces(mesh, file);
  OutBuffer o(out);
  o.text("OFF\n{} {} 0\n", f.used.size(), f.count);
  write_vertices(o, mesh, f, "");
  write_faces(o, f, true, 0);
  o.flush();
}

}  // namespace quadval::io
