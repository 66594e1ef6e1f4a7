// VTU writer: XML header with appended raw data, blocks in the order they are declared.
#include "io/vtu_write.hpp"

#include <bit>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>

#include <fmt/core.h>

#include "io/out_buffer.hpp"
#include "io/vtk_node_order.hpp"
#include "quadval/error.hpp"

namespace quadval::io {

namespace {

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

/// One appended array: its XML declaration, its size, and how to write its values (streamed
/// block by block: the connectivity and the other cell arrays of a million hexahedra are
/// never held in memory, 150 MB less).
struct Array {
  std::string type, name;
  int components;
  std::uint64_t bytes;
  std::function<void(OutBuffer&)> write;
};

// Values of one fixed-size type through a small staging buffer.
template <class T>
class Stream {
 public:
  explicit Stream(OutBuffer& o) : o_(o) {}
  ~Stream() { flush(); }
  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;
  void put(T v) {
    stage_[n_++] = v;
    if (n_ == kStage) flush();
  }
  void flush() {
    if (n_ > 0) o_.bytes_buffered(stage_, n_ * sizeof(T));
    n_ = 0;
  }

 private:
  static constexpr std::size_t kStage = 4096;
  OutBuffer& o_;
  T stage_[kStage];
  std::size_t n_ = 0;
};

// One value per cell, the blocks in order.
template <class T, class Value>
void write_per_cell(OutBuffer& o, const Mesh& mesh, Value value) {
  Stream<T> s(o);
  for (const ElementBlock& b : mesh.blocks)
    for (std::size_t e = 0; e < b.size(); ++e) s.put(static_cast<T>(value(b, e)));
}

}  // namespace

void write_vtu(const Mesh& mesh, std::ostream& out, std::span<const ElementField> fields, const std::string& file) {
  QV_ASSERT(mesh.coords.size() == 3 * mesh.num_nodes(), "coordinates do not match the nodes");
  std::uint64_t cells = 0, corners = 0;
  for (const ElementBlock& b : mesh.blocks) {
    const VtkCell& cell = vtk_cell(*b.type);
    if (!cell.exact && b.size() > 0)
      fmt::print(stderr, "quadval: warning: {}: {} elements of type {} ({}) written as {}\n", file, b.size(),
                 b.type->gmsh_id, b.type->name, cell.note);
    cells += b.size();
    corners += b.size() * cell.gmsh_node.size();
  }
  std::vector<Array> point_arrays, cell_arrays, cell_data;
  point_arrays.push_back({"Float64", "Points", 3, mesh.coords.size() * sizeof(double), [&](OutBuffer& o) {
                            o.bytes(mesh.coords.data(), mesh.coords.size() * sizeof(double));
                          }});
  cell_arrays.push_back({"Int64", "connectivity", 1, corners * sizeof(std::int64_t), [&](OutBuffer& o) {
                           Stream<std::int64_t> s(o);
                           for (const ElementBlock& b : mesh.blocks) {
                             const VtkCell& cell = vtk_cell(*b.type);
                             for (std::size_t e = 0; e < b.size(); ++e) {
                               const auto nodes = b.element(e);
                               for (int g : cell.gmsh_node) {
                                 const NodeIndex n = nodes[static_cast<std::size_t>(g)];
                                 // A throw here leaves no file: the writers write to a temporary.
                                 QV_ASSERT(n < mesh.num_nodes(), "node index out of range");
                                 s.put(n);
                               }
                             }
                           }
                         }});
  cell_arrays.push_back({"Int64", "offsets", 1, cells * sizeof(std::int64_t), [&](OutBuffer& o) {
                           Stream<std::int64_t> s(o);
                           std::int64_t offset = 0;
                           for (const ElementBlock& b : mesh.blocks) {
                             const auto k = static_cast<std::int64_t>(vtk_cell(*b.type).gmsh_node.size());
                             for (std::size_t e = 0; e < b.size(); ++e) s.put(offset += k);
                           }
                         }});
  cell_arrays.push_back({"UInt8", "types", 1, cells, [&](OutBuffer& o) {
                           write_per_cell<std::uint8_t>(
                               o, mesh, [](const ElementBlock& b, std::size_t) { return vtk_cell(*b.type).vtk_type; });
                         }});
  cell_data.push_back({"Int64", "element_tag", 1, cells * sizeof(std::int64_t), [&](OutBuffer& o) {
                         write_per_cell<std::int64_t>(o, mesh,
                                                      [](const ElementBlock& b, std::size_t e) { return b.tags[e]; });
                       }});
  cell_data.push_back({"Int32", "entity_tag", 1, cells * sizeof(std::int32_t), [&](OutBuffer& o) {
                         write_per_cell<std::int32_t>(o, mesh,
                                                      [](const ElementBlock& b, std::size_t) { return b.entity_tag; });
                       }});
  for (const ElementField& f : fields) {
    QV_ASSERT(f.values.size() == mesh.num_elements(), "field " << f.name << " has the wrong size");
    cell_data.push_back({"Float64", f.name, 1, f.values.size() * sizeof(double),
                         [&f](OutBuffer& o) { o.bytes(f.values.data(), f.values.size() * sizeof(double)); }});
  }

  OutBuffer o(out);
  std::uint64_t offset = 0;
  auto declare = [&](const Array& a) {
    o.text("        <DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"appended\" offset=\"{}\"/>\n",
           a.type, xml_escape(a.name), a.components, offset);
    offset += sizeof(std::uint64_t) + a.bytes;
  };
  o.text("<?xml version=\"1.0\"?>\n");
  o.text("<VTKFile type=\"UnstructuredGrid\" version=\"2.2\" byte_order=\"{}\" header_type=\"UInt64\">\n",
         std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian");
  o.text("  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", mesh.num_nodes(), cells);
  o.text("      <Points>\n");
  for (const Array& a : point_arrays) declare(a);
  o.text("      </Points>\n      <Cells>\n");
  for (const Array& a : cell_arrays) declare(a);
  o.text("      </Cells>\n      <CellData Scalars=\"element_tag\">\n");
  for (const Array& a : cell_data) declare(a);
  o.text("      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _");
  for (const auto* group : {&point_arrays, &cell_arrays, &cell_data}) {
    for (const Array& a : *group) {
      o.raw(a.bytes);
      a.write(o);
    }
  }
  o.text("\n  </AppendedData>\n</VTKFile>\n");
  o.flush();
}

}  // namespace quadval::io
