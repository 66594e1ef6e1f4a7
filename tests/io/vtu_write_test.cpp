// VTU output checked by VTK itself: one affinely mapped element of every registry type is
// written, read back with vtkXMLUnstructuredGridReader (tests/io/vtk_check.py), and each
// VTK point must sit where VTK's own parametric coordinate of that point, mapped through
// the element's affine map, puts it. Node positions come from Gmsh's reference nodes
// (gmsh.model.mesh.getElementProperties) where Gmsh has them.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <random>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "io/io_test_support.hpp"
#include "quadval/io.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

using testing_io::ScratchDir;

/// VTK type expected for each Gmsh type (vtkCellType.h; io.hpp says which is chosen).
int expected_vtk_type(const ElementType& t) {
  static const std::map<int, int> kSpecial = {{14, 27}, {16, 23}, {17, 25}, {18, 26}, {19, 27}};
  static const std::map<ElementFamily, int> kLinear = {
      {ElementFamily::point, 1},       {ElementFamily::line, 3},        {ElementFamily::triangle, 5},
      {ElementFamily::quadrangle, 9},  {ElementFamily::tetrahedron, 10}, {ElementFamily::hexahedron, 12},
      {ElementFamily::prism, 13},      {ElementFamily::pyramid, 14}};
  static const std::map<ElementFamily, int> kLagrange = {
      {ElementFamily::line, 68},        {ElementFamily::triangle, 69},   {ElementFamily::quadrangle, 70},
      {ElementFamily::tetrahedron, 71}, {ElementFamily::hexahedron, 72}, {ElementFamily::prism, 73}};
  if (kSpecial.count(t.gmsh_id)) return kSpecial.at(t.gmsh_id);
  if (t.has_lagrange_basis && t.complete && t.order >= 2 && kLagrange.count(t.family)) return kLagrange.at(t.family);
  if (kLinear.count(t.family) && t.num_nodes >= family_num_vertices(t.family)) return kLinear.at(t.family);
  return 2;  // VTK_POLY_VERTEX
}

int run(const std::string& cmd, std::string& output, const ScratchDir& dir) {
  const int status = std::system((cmd + " >" + (dir / "py_out.txt").string() + " 2>&1").c_str());
  output = testing_io::file_bytes(dir / "py_out.txt");
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(VtuWrite, VtkPlacesEveryNodeWhereItsParametricCoordinateSays) {
  ScratchDir dir("vtu");
  const std::string script = fmt::format("{} {}/tests/io/vtk_check.py", QUADVAL_PYTHON, QUADVAL_SOURCE_DIR);
  std::string output;
  nlohmann::json gmsh_refs = nlohmann::json::object();
  if (run(script + " refs " + (dir / "refs.json").string(), output, dir) == 0)
    gmsh_refs = nlohmann::json::parse(testing_io::file_bytes(dir / "refs.json"));
  else
    std::cout << "[ note ] no Gmsh reference nodes (" << output << "), using reference_nodes()\n";

  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Mesh mesh;
  nlohmann::json expect = nlohmann::json::array();
  std::vector<double> twice;
  Tag tag = 100;
  std::size_t from_gmsh = 0;
  for (const ElementType& t : element_types()) {
    if (t.num_nodes == 0) continue;
    // Reference nodes: Gmsh's own when it has them, else quadval's (Lagrange types only).
    std::vector<RefPoint> ref;
    const std::string key = std::to_string(t.gmsh_id);
    if (t.has_lagrange_basis && gmsh_refs.contains(key)) {
      for (const auto& p : gmsh_refs[key]) ref.push_back({p[0].get<double>(), p[1].get<double>(), p[2].get<double>()});
      ++from_gmsh;
    } else if (t.has_lagrange_basis) {
      const auto r = reference_nodes(t);
      ref.assign(r.begin(), r.end());
    }
    // x = A r + b with A near the identity (well conditioned), so nodes stay distinct.
    std::array<std::array<double, 3>, 3> A{};
    std::array<double, 3> b{};
    for (int i = 0; i < 3; ++i) {
      b[i] = 10 * unit(rng);
      for (int j = 0; j < 3; ++j) A[i][j] = (i == j ? 2.0 : 0.0) + 0.3 * unit(rng);
    }
    ElementBlock block;
    block.type = &t;
    block.entity_dim = t.dim;
    block.entity_tag = 1;
    block.tags = {tag};
    for (int n = 0; n < t.num_nodes; ++n) {
      block.nodes.push_back(static_cast<NodeIndex>(mesh.num_nodes()));
      mesh.node_tags.push_back(mesh.num_nodes() + 1);
      for (int d = 0; d < 3; ++d) {
        double x = unit(rng);
        if (!ref.empty()) {
          x = b[d];
          for (int k = 0; k < 3; ++k) x += A[d][k] * ref[static_cast<std::size_t>(n)][static_cast<std::size_t>(k)];
        }
        mesh.coords.push_back(x);
      }
    }
    const int vtk_type = expected_vtk_type(t);
    expect.push_back({{"gmsh_type", t.gmsh_id}, {"vtk_type", vtk_type}, {"family", std::string(family_name(t.family))},
                      {"A", A}, {"b", b}, {"geometric", !ref.empty() && vtk_type != 2}, {"tag", tag}});
    twice.push_back(2.0 * static_cast<double>(tag));
    mesh.blocks.push_back(std::move(block));
    tag += 3;
  }
  EXPECT_GE(from_gmsh, gmsh_refs.empty() ? 0u : 90u);
  const ElementField field{"twice_tag", twice};
  write_mesh(mesh, dir / "all.vtu", {MeshFormat::vtu, false}, std::span<const ElementField>(&field, 1));
  testing_io::write_bytes(dir / "expect.json", expect.dump());
  const int code = run(script + " check " + (dir / "all.vtu").string() + " " + (dir / "expect.json").string(), output, dir);
  if (code == 77) GTEST_SKIP() << "vtk Python module missing: " << output;
  EXPECT_EQ(code, 0) << output;
  EXPECT_THAT(output, ::testing::HasSubstr(fmt::format("{} cells checked, 0 failures", expect.size())));
}

TEST(VtuWrite, HeaderDeclaresVersion22AndAppendedRawData) {
  ScratchDir dir("vtu_header");
  const Mesh m = read_mesh(std::filesystem::path(QUADVAL_SHARED_DIR) / "data/curved/quad_h0.4_o2.msh");
  write_mesh(m, dir / "q.vtu", {MeshFormat::vtu, false});
  const std::string text = testing_io::file_bytes(dir / "q.vtu");
  EXPECT_THAT(text, ::testing::HasSubstr("<VTKFile type=\"UnstructuredGrid\" version=\"2.2\""));
  EXPECT_THAT(text, ::testing::HasSubstr("<AppendedData encoding=\"raw\">"));
  EXPECT_THAT(text, ::testing::HasSubstr(fmt::format("NumberOfPoints=\"{}\" NumberOfCells=\"{}\"", m.num_nodes(), m.num_elements())));
  EXPECT_THAT(text, ::testing::HasSubstr("Name=\"element_tag\""));
}

TEST(VtuWrite, FieldOfTheWrongSizeIsRejected) {
  ScratchDir dir("vtu_field");
  const Mesh m = read_mesh(std::filesystem::path(QUADVAL_SHARED_DIR) / "data/tri/rect-sin-a6.msh");
  const ElementField bad{"q", std::vector<double>(3, 1.0)};
  EXPECT_THROW(write_mesh(m, dir / "q.vtu", {MeshFormat::vtu, false}, std::span<const ElementField>(&bad, 1)),
               std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(dir / "q.vtu"));
}

}  // namespace
}  // namespace quadval
