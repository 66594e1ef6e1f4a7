// End-to-end `quadval check --measure mu|scaled-jacobian|all`: closed forms on straight
// meshes (equilateral triangles: mu = sj = 1; rhombi of angle t: sj = sin t, mu = tan t/2),
// the CSV columns, JSON and VTU fields, skipped types said so, unchanged exit codes.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_run.hpp"
#include "quadval/element_type.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

namespace fs = std::filesystem;
using testing_cli::CliRun;
using testing_cli::run_cli;

using testing_cli::slurp;

// A MSH 2.2 file of one element type (Gmsh id) from nodes and connectivity (1-based).
void write_msh(const fs::path& path, const std::vector<std::array<double, 3>>& nodes, int type,
               const std::vector<std::vector<int>>& elements) {
  std::ofstream f(path);
  f.precision(17);
  f << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" << nodes.size() << "\n";
  for (std::size_t i = 0; i < nodes.size(); ++i)
    f << i + 1 << " " << nodes[i][0] << " " << nodes[i][1] << " " << nodes[i][2] << "\n";
  f << "$EndNodes\n$Elements\n" << elements.size() << "\n";
  for (std::size_t e = 0; e < elements.size(); ++e) {
    f << e + 1 << " " << type << " 2 1 1";
    for (int n : elements[e]) f << " " << n;
    f << "\n";
  }
  f << "$EndElements\n";
}

// Rows of a CSV as maps header -> cell.
std::vector<std::map<std::string, std::string>> read_csv(const fs::path& p) {
  std::istringstream in(slurp(p));
  std::string line;
  std::getline(in, line);
  std::vector<std::string> head;
  {
    std::stringstream ss(line);
    std::string c;
    while (std::getline(ss, c, ',')) head.push_back(c);
  }
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string c;
    std::map<std::string, std::string> row;
    for (const std::string& h : head) {
      std::getline(ss, c, ',');
      row[h] = c;
    }
    rows.push_back(row);
  }
  return rows;
}

class QualityCli : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("quadval_quality_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    // A strip of 6 equilateral triangles (side 1), counter-clockwise.
    const double h = std::sqrt(3.0) / 2;
    std::vector<std::array<double, 3>> tn;
    for (int i = 0; i < 4; ++i) tn.push_back({double(i), 0, 0});
    for (int i = 0; i < 4; ++i) tn.push_back({i + 0.5, h, 0});
    std::vector<std::vector<int>> tris;
    for (int i = 0; i < 3; ++i) {
      tris.push_back({1 + i, 2 + i, 5 + i});
      tris.push_back({2 + i, 6 + i, 5 + i});
    }
    write_msh(dir_ / "equilateral.msh", tn, 2, tris);
    // A 3 x 2 grid of rhombi of side 1 and angle 1 rad.
    std::vector<std::array<double, 3>> qn;
    for (int j = 0; j <= 2; ++j)
      for (int i = 0; i <= 3; ++i) qn.push_back({i + j * std::cos(1.0), j * std::sin(1.0), 0});
    std::vector<std::vector<int>> quads;
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i) {
        const int a = 1 + j * 4 + i;
        quads.push_back({a, a + 1, a + 5, a + 4});
      }
    write_msh(dir_ / "rhombi.msh", qn, 3, quads);
    // The same with one quadrangle made non-convex (inverted corner).
    qn[5] = {qn[0][0] + 0.3, qn[0][1] + 0.1, 0};
    write_msh(dir_ / "inverted.msh", qn, 3, quads);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  const std::string data_ = QUADVAL_SHARED_DIR "/data/curved/";
};

TEST_F(QualityCli, EquilateralTrianglesHaveScaledJacobianOne) {
  const fs::path csv = dir_ / "t.csv";
  const CliRun r = run_cli("check " + (dir_ / "equilateral.msh").string() + " --measure scaled-jacobian --tol 1e-6 -o " +
                           csv.string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("scaled Jacobian"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("ICN/IGE are related but not equal measures"), std::string::npos) << r.output;
  const auto rows = read_csv(csv);
  ASSERT_EQ(rows.size(), 6u);
  for (const auto& row : rows) {
    EXPECT_NEAR(std::stod(row.at("sj_lower")), 1, 1e-6);
    EXPECT_GE(std::stod(row.at("sj_upper")), 1 - 1e-12);
    EXPECT_LE(std::stod(row.at("sj_lower")), 1 + 1e-12);
    EXPECT_EQ(row.at("mu_lower"), "nan");  // not asked for
  }
}

TEST_F(QualityCli, RhombiHaveSineAndHalfAngleTangent) {
  const fs::path csv = dir_ / "q.csv";
  const CliRun r = run_cli("check " + (dir_ / "rhombi.msh").string() + " --measure all --tol 1e-6 -o " + csv.string());
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string text = slurp(csv);
  const std::string header = text.substr(0, text.find('\n'));
  EXPECT_EQ(header,
            "tag,type,validity,jmin_lower,jmin_upper,jmax_lower,jmax_upper,distortion_lower,subdivisions,"
            "distortion_upper,jmin_over_javg,ratio_lower,stage,exact,mu_lower,mu_upper,sj_lower,sj_upper");
  const auto rows = read_csv(csv);
  ASSERT_EQ(rows.size(), 6u);
  for (const auto& row : rows) {
    // sj: the sine of the angle; mu: sigma_min / sigma_max of [a b], |a| = |b| = 1,
    // a.b = cos t: sqrt((1 - cos t) / (1 + cos t)) = tan(t / 2).
    EXPECT_LE(std::stod(row.at("sj_lower")), std::sin(1.0) + 1e-12);
    EXPECT_GE(std::stod(row.at("sj_upper")), std::sin(1.0) - 1e-12);
    EXPECT_NEAR(std::stod(row.at("sj_lower")), std::sin(1.0), 1e-6);
    EXPECT_LE(std::stod(row.at("mu_lower")), std::tan(0.5) + 1e-12);
    EXPECT_GE(std::stod(row.at("mu_upper")), std::tan(0.5) - 1e-12);
    EXPECT_NEAR(std::stod(row.at("mu_lower")), std::tan(0.5), 1e-6);
    EXPECT_NE(row.at("distortion_lower"), "nan");  // all = distortion + mu + sj
  }
  EXPECT_NE(r.output.find("worst"), std::string::npos);
}

TEST_F(QualityCli, JsonAndVtuCarryTheQualityFields) {
  const fs::path json = dir_ / "q.json", vtu = dir_ / "q.vtu";
  const CliRun r = run_cli("check " + (dir_ / "rhombi.msh").string() + " --measure all -q -o " + json.string() + " -o " +
                           vtu.string());
  ASSERT_EQ(r.code, 0) << r.output;
  const auto j = nlohmann::json::parse(slurp(json));
  EXPECT_EQ(j["summary"]["measure"], "all");
  EXPECT_EQ(j["summary"]["scaled_jacobian"]["computed"], 6);
  EXPECT_EQ(j["summary"]["mu"]["computed"], 6);
  ASSERT_EQ(j["elements"].size(), 6u);
  EXPECT_NEAR(j["elements"][0]["sj"]["lower"].get<double>(), std::sin(1.0), 1e-2);
  EXPECT_NEAR(j["elements"][0]["mu"]["lower"].get<double>(), std::tan(0.5), 1e-2);
  const std::string v = slurp(vtu);
  EXPECT_NE(v.find("\"mu_lower\""), std::string::npos);
  EXPECT_NE(v.find("\"sj_lower\""), std::string::npos);
}

TEST_F(QualityCli, InvertedElementExitsOneWithNegativeScaledJacobian) {
  const fs::path csv = dir_ / "i.csv";
  const CliRun r = run_cli("check " + (dir_ / "inverted.msh").string() + " --measure scaled-jacobian -o " + csv.string());
  EXPECT_EQ(r.code, 1) << r.output;
  std::size_t negative = 0;
  for (const auto& row : read_csv(csv)) {
    if (row.at("validity") == "invalid") {
      EXPECT_LE(std::stod(row.at("sj_lower")), 0) << row.at("tag");  // J <= 0 somewhere
      ++negative;
    } else {
      EXPECT_GT(std::stod(row.at("sj_lower")), 0) << row.at("tag");
    }
  }
  EXPECT_GE(negative, 1u);
  // Element 1 has its third vertex pulled inside: its corner there is clearly inverted.
  EXPECT_LT(std::stod(read_csv(csv).front().at("sj_upper")), -0.1);
}

TEST_F(QualityCli, UnsupportedTypesAreReportedAsSkipped) {
  // An order-5 pyramid: validity and mu are computed (mu covers every type of the Jacobian
  // bounds), the scaled Jacobian (pyramids up to order 4) skips it and says so; the exit
  // code is the validity's.
  const ElementType& p5 = *find_element_type(120);
  std::vector<std::array<double, 3>> nodes;
  std::vector<int> conn;
  for (const auto& r : reference_nodes(p5)) {
    nodes.push_back({r[0], r[1], r[2]});
    conn.push_back(static_cast<int>(nodes.size()));
  }
  const std::string mesh = (dir_ / "pyramid_o5.msh").string();
  write_msh(mesh, nodes, 120, {conn});
  const fs::path csv = dir_ / "p.csv";
  const CliRun v = run_cli("check " + mesh + " -q");
  const CliRun r = run_cli("check " + mesh + " --measure all -o " + csv.string());
  EXPECT_EQ(v.code, 0) << v.output;
  EXPECT_EQ(r.code, v.code) << r.output;
  EXPECT_NE(r.output.find("skipped for scaled Jacobian"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("skipped for mu"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("computed 0, skipped 1"), std::string::npos) << r.output;
  for (const auto& row : read_csv(csv)) {
    EXPECT_EQ(row.at("sj_lower"), "nan");
    // Gmsh's reference pyramid (apex height 1) is the ideal one (equilateral faces, apex
    // height sqrt 2) squashed along z: W = diag(1, 1, 1/sqrt 2), mu = 1/sqrt 2.
    EXPECT_LE(std::stod(row.at("mu_lower")), std::sqrt(0.5) + 1e-12);
    EXPECT_GE(std::stod(row.at("mu_upper")), std::sqrt(0.5) - 1e-12);
    EXPECT_LE(std::stod(row.at("mu_upper")) - std::stod(row.at("mu_lower")), 1e-2);
  }
}

TEST_F(QualityCli, ResultsDoNotDependOnThreads) {
  const std::string mesh = data_ + "tets_h0.8_o2.msh";
  const fs::path a = dir_ / "t1.csv", b = dir_ / "t2.csv";
  run_cli("check " + mesh + " --measure all --threads 1 -q -o " + a.string());
  run_cli("check " + mesh + " --measure all --threads 2 -q -o " + b.string());
  const std::string ta = slurp(a);
  EXPECT_GT(ta.size(), 1000u);
  EXPECT_EQ(ta, slurp(b));
}

TEST_F(QualityCli, BadOptionValuesExitTwo) {
  const std::string mesh = (dir_ / "rhombi.msh").string();
  const CliRun a = run_cli("check " + mesh + " --measure scaled_jacobian");
  EXPECT_EQ(a.code, 2);
  EXPECT_NE(a.output.find("measure"), std::string::npos) << a.output;
  const CliRun b = run_cli("check " + mesh + " --measure mu --tol -1");
  EXPECT_EQ(b.code, 2);
  EXPECT_NE(b.output.find("tol"), std::string::npos) << b.output;
  EXPECT_EQ(run_cli("check " + (dir_ / "missing.msh").string() + " --measure mu").code, 2);
}

TEST_F(QualityCli, HelpNamesTheMeasuresAndGmshsRelatedOnes) {
  const CliRun r = run_cli("check --help");
  EXPECT_NE(r.output.find("scaled-jacobian"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("ICN/IGE"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace quadval
