// VTU writer: XML header with appended raw data, blocks in the order they are declared.
#include "io/vtu_write.hpp"

#include <bit>
#include <cstdint>
#include <cstdio>
#include <cstring>

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

/// One appended array: its XML declaration and its bytes.
struct Array {
  std::string type, name;
  int components;
  std::vector<char> bytes;

  template <class T>
  static Array of(std::string type, std::string name, int components, const std::vector<T>& values) {
    Array a{std::move(type), std::move(name), components, {}};
    a.bytes.resize(values.size() * sizeof(T));
    if (!values.empty()) std::memcpy(a.bytes.data(), values.data(), a.bytes.size());
    return a;
  }
};

}  // namespace

void write_vtu(const Mesh& mesh, std::ostream& out, std::span<const ElementField> fields, const std::string& file) {
  QV_ASSERT(mesh.coords.size() == 3 * mesh.num_nodes(), "coordinates do not match the nodes");
  std::vector<std::int64_t> connectivity, offsets;
  std::vector<std::uint8_t> types;
  std::vector<std::int64_t> element_tags;
  std::vector<std::int32_t> entity_tags;
  connectivity.reserve(mesh.num_elements() * 4);
  offsets.reserve(mesh.num_elements());
  for (const ElementBlock& b : mesh.blocks) {
    const VtkCell& cell = vtk_cell(*b.type);
    if (!cell.exact && b.size() > 0)
      fmt::print(stderr, "quadval: warning: {}: {} elements of type {} ({}) written as {}\n", file, b.size(),
                 b.type->gmsh_id, b.type->name, cell.note);
    for (std::size_t e = 0; e < b.size(); ++e) {
      const auto nodes = b.element(e);
      for (int g : cell.gmsh_node) {
        QV_ASSERT(nodes[static_cast<std::size_t>(g)] < mesh.num_nodes(), "node index out of range");
        connectivity.push_back(nodes[static_cast<std::size_t>(g)]);
      }
      offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
      types.push_back(static_cast<std::uint8_t>(cell.vtk_type));
      element_tags.push_back(static_cast<std::int64_t>(b.tags[e]));
      entity_tags.push_back(b.entity_tag);
    }
  }
  std::vector<Array> point_arrays, cell_arrays, cell_data;
  point_arrays.push_back(Array::of("Float64", "Points", 3, mesh.coords));
  cell_arrays.push_back(Array::of("Int64", "connectivity", 1, connectivity));
  cell_arrays.push_back(Array::of("Int64", "offsets", 1, offsets));
  cell_arrays.push_back(Array::of("UInt8", "types", 1, types));
  cell_data.push_back(Array::of("Int64", "element_tag", 1, element_tags));
  cell_data.push_back(Array::of("Int32", "entity_tag", 1, entity_tags));
  for (const ElementField& f : fields) {
    QV_ASSERT(f.values.size() == mesh.num_elements(), "field " << f.name << " has the wrong size");
    cell_data.push_back(Array::of("Float64", f.name, 1, f.values));
  }

  OutBuffer o(out);
  std::uint64_t offset = 0;
  auto declare = [&](const Array& a) {
    o.text("        <DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"appended\" offset=\"{}\"/>\n",
           a.type, xml_escape(a.name), a.components, offset);
    offset += sizeof(std::uint64_t) + a.bytes.size();
  };
  o.text("<?xml version=\"1.0\"?>\n");
  o.text("<VTKFile type=\"UnstructuredGrid\" version=\"2.2\" byte_order=\"{}\" header_type=\"UInt64\">\n",
         std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian");
  o.text("  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", mesh.num_nodes(),
         types.size());
  o.text("      <Points>\n");
  for (const Array& a : point_arrays) declare(a);
  o.text("      </Points>\n      <Cells>\n");
  for (const Array& a : cell_arrays) declare(a);
  o.text("      </Cells>\n      <CellData Scalars=\"element_tag\">\n");
  for (const Array& a : cell_data) declare(a);
  o.text("      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _");
  for (const auto* group : {&point_arrays, &cell_arrays, &cell_data}) {
    for (const Array& a : *group) {
      o.raw(static_cast<std::uint64_t>(a.bytes.size()));
      o.bytes(a.bytes.data(), a.bytes.size());
    }
  }
  o.text("\n  </AppendedData>\n</VTKFile>\n");
  o.flush();
}

}  // namespace quadval::io
