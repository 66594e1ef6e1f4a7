// End-to-end `quadval check`: exit codes (0 all valid, 1 invalid found, 2 bad input), the
// CSV header and content against Gmsh's counts, JSON, VTU/MSH with fields, thread
// independence.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <sys/wait.h>

#include "cli_run.hpp"
#include "quadval/bezier_basis.hpp"
#include "quadval/io.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

namespace fs = std::filesystem;

using testing_cli::CliRun;
using testing_cli::run_cli;

using testing_cli::slurp;

class CheckCli : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("quadval_check_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  const std::string data_ = QUADVAL_SHARED_DIR "/data/curved/";
};

TEST_F(CheckCli, QuadMeshFindsGmshsInvalidCountAndWritesCsv) {
  const fs::path csv = dir_ / "q.csv";
  const CliRun r = run_cli("check " + data_ + "quad_h0.4_o2.msh -o " + csv.string());
  EXPECT_EQ(r.code, 1) << r.output;  // Gmsh reports 28 invalid elements
  EXPECT_NE(r.output.find("invalid 28"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("stage table"), std::string::npos) << r.output;
  const std::string text = slurp(csv);
  const std::string header = text.substr(0, text.find('\n'));
  EXPECT_EQ(header.rfind("tag,type,validity,jmin_lower,jmin_upper,jmax_lower,jmax_upper,distortion_lower,subdivisions", 0), 0u)
      << header;
  std::size_t rows = 0, invalid = 0;
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    ++rows;
    std::stringstream ss(line);
    std::string tag, type, validity, lo, hi;
    std::getline(ss, tag, ',');
    std::getline(ss, type, ',');
    std::getline(ss, validity, ',');
    std::getline(ss, lo, ',');
    std::getline(ss, hi, ',');
    EXPECT_EQ(type, "10");
    EXPECT_TRUE(validity == "valid" || validity == "invalid") << line;
    if (validity == "invalid") {
      ++invalid;
      EXPECT_LE(std::stod(hi), 0) << line;
    } else {
      EXPECT_GT(std::stod(lo), 0) << line;
    }
  }
  EXPECT_EQ(rows, 511u);
  EXPECT_EQ(invalid, 28u);
}

TEST_F(CheckCli, AllValidMeshExitsZeroAndJsonVtuMshAreWritten) {
  // A mesh of two straight quadratic triangles (valid), written by our own writer.
  Mesh m;
  const ElementType& t6 = *find_element_type(9);
  for (const auto& p : reference_nodes(t6)) {
    m.node_tags.push_back(m.node_tags.size() + 1);
    m.coords.insert(m.coords.end(), {p[0], p[1], 0});
  }
  ElementBlock b;
  b.type = &t6;
  b.entity_dim = 2;
  b.entity_tag = 1;
  b.tags = {1};
  for (NodeIndex i = 0; i < 6; ++i) b.nodes.push_back(i);
  m.blocks.push_back(b);
  const fs::path in = dir_ / "ok.msh";
  write_mesh(m, in);
  const fs::path json = dir_ / "ok.json", vtu = dir_ / "ok.vtu", msh = dir_ / "ok_fields.msh";
  const CliRun r = run_cli("check " + in.string() + " --measure distortion --threads 2 -o " + json.string() +
                           " -o " + vtu.string() + " -o " + msh.string());
  EXPECT_EQ(r.code, 0) << r.output;
  const auto j = nlohmann::json::parse(slurp(json));
  EXPECT_EQ(j["summary"]["valid"], 1);
  EXPECT_EQ(j["elements"][0]["validity"], "valid");
  EXPECT_NEAR(j["elements"][0]["distortion"][0].get<double>(), 1.0, 1e-9);
  EXPECT_TRUE(fs::exists(vtu));
  EXPECT_NE(slurp(vtu).find("distortion_lower"), std::string::npos);
  EXPECT_NE(slurp(msh).find("$ElementData"), std::string::npos);
  EXPECT_EQ(run_cli("check -q " + in.string()).output, "");
  // The fields' $ElementData is skipped with a warning, which --quiet leaves out too.
  EXPECT_NE(run_cli("check " + msh.string()).err.find("$ElementData is not used"), std::string::npos);
  EXPECT_EQ(run_cli("check -q " + msh.string()).output, "");
}

TEST_F(CheckCli, BadInputExitsTwo) {
  EXPECT_EQ(run_cli("check " + (dir_ / "missing.msh").string()).code, 2);
  const fs::path garbage = dir_ / "garbage.msh";
  std::ofstream(garbage) << "$MeshFormat\nnot a mesh\n";
  const CliRun r = run_cli("check " + garbage.string());
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("garbage.msh"), std::string::npos) << r.output;
  EXPECT_EQ(run_cli("check " + data_ + "quad_h0.4_o2.msh -o " + (dir_ / "x.txt").string()).code, 2);
  EXPECT_EQ(run_cli("check " + data_ + "quad_h0.4_o2.msh --measure nonsense").code, 2);
  // Coordinates so far apart that J would overflow: refused, rather than bounds of inf.
  const fs::path huge = dir_ / "huge.msh";
  std::ofstream(huge) << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1e150 0 0\n"
                         "3 0 1e150 0\n4 0 0 1e150\n$EndNodes\n$Elements\n1\n1 4 2 0 1 1 2 3 4\n$EndElements\n";
  const CliRun h = run_cli("check " + huge.string() + " --measure all");
  EXPECT_EQ(h.code, 2) << h.output;
  EXPECT_NE(h.output.find("huge.msh"), std::string::npos) << h.output;
  EXPECT_NE(h.output.find("rescale"), std::string::npos) << h.output;
}

// An element whose order is beyond the supported ones is skipped, said so, and keeps the
// exit status at 1 (not certified valid).
TEST_F(CheckCli, UnsupportedOrderIsSkippedAndSaidSo) {
  const ElementType* type =
      find_element_type(ElementFamily::hexahedron, max_supported_order(ElementFamily::hexahedron) + 1, true);
  if (type == nullptr) GTEST_SKIP() << "every hexahedron order is supported";
  Mesh m;
  for (const auto& p : reference_nodes(*type)) {
    m.node_tags.push_back(m.node_tags.size() + 1);
    m.coords.insert(m.coords.end(), {p[0], p[1], p[2]});
  }
  ElementBlock b;
  b.type = type;
  b.entity_dim = 3;
  b.entity_tag = 1;
  b.tags = {7};
  for (NodeIndex i = 0; i < static_cast<NodeIndex>(type->num_nodes); ++i) b.nodes.push_back(i);
  m.blocks.push_back(b);
  const fs::path in = dir_ / "high.msh";
  write_mesh(m, in);
  const CliRun r = run_cli("check " + in.string());
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("skipped 1"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("not analysed"), std::string::npos) << r.output;
}

TEST_F(CheckCli, ResultsDoNotDependOnThreads) {
  const fs::path a = dir_ / "a.csv", b = dir_ / "b.csv";
  const std::string mesh = data_ + "warped_tetrahedron_o3_N6_a0.25.msh";
  run_cli("check " + mesh + " --measure jacobian --threads 1 -q -o " + a.string());
  run_cli("check " + mesh + " --measure jacobian --threads 2 -q -o " + b.string());
  EXPECT_FALSE(slurp(a).empty());
  EXPECT_EQ(slurp(a), slurp(b));
}

}  // namespace
}  // namespace quadval
