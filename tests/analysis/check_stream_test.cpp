// check_mesh_streamed: the summary kept while elements stream by (bounded worst lists,
// histograms, sums in element order) equals the one computed from all stored results
// (summarize: sorting, not heaps), for 1 and 2 threads; CSV, JSON and mesh fields written
// batch by batch are byte for byte what the stored report gives; and the CLI's files equal
// the library's.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "jacobian_test_util.hpp"
#include "quadval/check_report.hpp"
#include "quadval/error.hpp"
#include "quadval/io.hpp"

namespace quadval {
namespace {

std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }

void expect_same_counts(const QualityCounts& a, const QualityCounts& b) {
  EXPECT_EQ(a.computed, b.computed);
  EXPECT_EQ(a.skipped, b.skipped);
  EXPECT_EQ(a.tolerance_not_met, b.tolerance_not_met);
  EXPECT_EQ(a.skipped_types, b.skipped_types);
}

void expect_same_worst(const WorstList& a, const WorstList& b) {
  const auto wa = a.sorted(), wb = b.sorted();
  ASSERT_EQ(wa.size(), wb.size());
  for (std::size_t k = 0; k < wa.size(); ++k) {
    EXPECT_EQ(wa[k].index, wb[k].index) << k;
    EXPECT_EQ(wa[k].tag, wb[k].tag) << k;
    EXPECT_EQ(wa[k].type, wb[k].type) << k;
    EXPECT_EQ(bits(wa[k].key), bits(wb[k].key)) << k;
    EXPECT_EQ(bits(wa[k].bounds.jmin_lower), bits(wb[k].bounds.jmin_lower)) << k;
    EXPECT_EQ(wa[k].bounds.validity, wb[k].bounds.validity) << k;
    EXPECT_EQ(bits(wa[k].quality.lower), bits(wb[k].quality.lower)) << k;
    EXPECT_EQ(bits(wa[k].quality.upper), bits(wb[k].quality.upper)) << k;
  }
}

// Everything but the timings (seconds, the stage table's CPU seconds).
void expect_same_summary(const CheckSummary& a, const CheckSummary& b) {
  EXPECT_EQ(a.file, b.file);
  EXPECT_EQ(a.measure, b.measure);
  EXPECT_EQ(a.dimension, b.dimension);
  EXPECT_EQ(a.planar, b.planar);
  EXPECT_EQ(a.elements, b.elements);
  EXPECT_EQ(a.counts, b.counts);
  ASSERT_EQ(a.stages.size(), b.stages.size());
  for (std::size_t i = 0; i < a.stages.size(); ++i) {
    EXPECT_EQ(a.stages[i].name, b.stages[i].name);
    EXPECT_EQ(a.stages[i].valid, b.stages[i].valid) << a.stages[i].name;
    EXPECT_EQ(a.stages[i].invalid, b.stages[i].invalid) << a.stages[i].name;
  }
  EXPECT_EQ(a.exact_fallbacks, b.exact_fallbacks);
  EXPECT_EQ(a.histogram, b.histogram);
  expect_same_worst(a.worst, b.worst);
  for (auto [qa, qb] : {std::pair{&a.mu, &b.mu}, std::pair{&a.sj, &b.sj}}) {
    expect_same_counts(qa->counts, qb->counts);
    EXPECT_EQ(qa->histogram, qb->histogram);
    EXPECT_EQ(bits(qa->lower_sum), bits(qb->lower_sum));
    expect_same_worst(qa->worst, qb->worst);
  }
}

// One streamed run that also keeps every batch (as check_mesh does) and writes CSV, JSON
// and fields batch by batch, so the stored and streamed outputs share one set of timings.
struct StreamedRun {
  CheckSummary summary;
  CheckReport report;
  std::string csv, json;
  std::vector<std::pair<std::string, std::vector<double>>> fields;
  std::size_t batches = 0;
};

// The JSON of one element built field by field with nlohmann (the writer formats it by hand):
// non-finite doubles are null.
nlohmann::json element_dom(const ElementCheck& e, const DistortionBounds& d, const QualityBounds& mu,
                           const QualityBounds& sj) {
  using nlohmann::json;
  const auto jnum = [](double x) { return std::isfinite(x) ? json(x) : json(nullptr); };
  const JacobianBounds& b = e.bounds;
  json je = {{"tag", e.tag},
             {"type", e.type->gmsh_id},
             {"validity", e.analysed ? validity_name(b.validity) : "skipped"}};
  if (e.analysed) {
    je["jmin"] = {jnum(b.jmin_lower), jnum(b.jmin_upper)};
    je["jmax"] = {jnum(b.jmax_lower), jnum(b.jmax_upper)};
    je["distortion"] = {jnum(d.lower), jnum(d.upper)};
    je["ratio_lower"] = jnum(e.ratio_lower());
    je["jmin_over_javg"] = jnum(e.jmin_over_javg());
    je["subdivisions"] = b.subdivisions;
    je["stage"] = b.stage;
    je["exact"] = b.exact;
    for (const auto& [name, q] : {std::pair{"mu", mu}, std::pair{"sj", sj}})
      if (!std::isnan(q.lower))
        je[name] = {{"lower", jnum(q.lower)}, {"upper", jnum(q.upper)}, {"subdivisions", q.subdivisions},
                    {"tolerance_met", q.tolerance_met}};
  }
  return je;
}

StreamedRun streamed_run(const Mesh& mesh, const CheckOptions& o, const std::string& file) {
  StreamedRun run;
  std::ostringstream json;
  CheckJsonWriter writer(json);
  CheckFieldCollector fields(mesh, o.measure);
  run.csv = check_csv_header();
  std::size_t next = 0;
  run.summary = check_mesh_streamed(mesh, o, file, [&](const CheckBatch& b) {
    EXPECT_EQ(b.first, next);  // in element order, nothing skipped or repeated
    EXPECT_LE(b.elements.size(), kCheckBatch);
    next += b.elements.size();
    ++run.batches;
    append_check_csv_rows(run.csv, b);
    writer.add(b);
    fields.add(b);
    CheckReport& r = run.report;
    r.elements.insert(r.elements.end(), b.elements.begin(), b.elements.end());
    if (!b.distortion.empty()) r.distortion.insert(r.distortion.end(), b.distortion.begin(), b.distortion.end());
    if (!b.mu.empty()) r.mu.insert(r.mu.end(), b.mu.begin(), b.mu.end());
    if (!b.sj.empty()) r.sj.insert(r.sj.end(), b.sj.begin(), b.sj.end());
  });
  writer.finish(run.summary);
  run.json = json.str();
  run.fields = fields.take();
  const CheckSummary& s = run.summary;
  CheckReport& r = run.report;
  r.file = s.file;
  r.measure = s.measure;
  r.dimension = s.dimension;
  r.planar = s.planar;
  r.counts = s.counts;
  r.stages = s.stages;
  r.exact_fallbacks = s.exact_fallbacks;
  r.mu_counts = s.mu.counts;
  r.sj_counts = s.sj.counts;
  r.seconds = s.seconds;
  r.threads = s.threads;
  return run;
}

void expect_same_fields(const std::vector<std::pair<std::string, std::vector<double>>>& a,
                        const std::vector<std::pair<std::string, std::vector<double>>>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t f = 0; f < a.size(); ++f) {
    EXPECT_EQ(a[f].first, b[f].first);
    ASSERT_EQ(a[f].second.size(), b[f].second.size()) << a[f].first;
    for (std::size_t i = 0; i < a[f].second.size(); ++i)
      ASSERT_EQ(bits(a[f].second[i]), bits(b[f].second[i])) << a[f].first << " element " << i;
  }
}

// The streamed run against check_mesh (stored) and against itself on 1 and 2 threads.
void check_both_modes(const Mesh& mesh, CheckOptions o, const std::string& file) {
  std::vector<CheckSummary> summaries;
  for (int threads : {1, 2}) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    o.threads = threads;
    const StreamedRun run = streamed_run(mesh, o, file);
    // The summary kept while streaming equals the one of all stored results ...
    expect_same_summary(run.summary, summarize(run.report, o.worst));
    // ... and of check_mesh, which stores them all.
    const CheckReport stored = check_mesh(mesh, o, file);
    expect_same_summary(run.summary, summarize(stored, o.worst));
    // ... and of a run with no sink, which keeps no per-element records.
    expect_same_summary(run.summary, check_mesh_streamed(mesh, o, file, {}));
    EXPECT_EQ(format_check_summary(run.summary, o.worst), format_check_summary(run.report, o.worst));
    // Files written batch by batch are the stored report's, byte for byte.
    EXPECT_EQ(run.csv, check_csv(run.report));
    EXPECT_EQ(run.csv, check_csv(stored));
    EXPECT_EQ(run.json, check_json(run.report));
    // Each element of the JSON as nlohmann builds it, field by field.
    const nlohmann::json parsed = nlohmann::json::parse(run.json);
    ASSERT_EQ(parsed["elements"].size(), run.report.elements.size());
    for (std::size_t i = 0; i < run.report.elements.size(); ++i)
      ASSERT_EQ(parsed["elements"][i], element_dom(run.report.elements[i], run.report.distortion_of(i),
                                                   run.report.mu_of(i), run.report.sj_of(i)))
          << "element " << i;
    expect_same_fields(run.fields, check_fields(mesh, run.report));
    summaries.push_back(run.summary);
  }
  expect_same_summary(summaries[0], summaries[1]);
}

class CheckStreamShared : public testing::TestWithParam<const char*> {};

TEST_P(CheckStreamShared, StreamedEqualsStored) {
  const std::string path = std::string(QUADVAL_SHARED_DIR) + "/data/curved/" + GetParam() + ".msh";
  const Mesh mesh = read_mesh(path);
  CheckOptions o;
  check_both_modes(mesh, o, path);
  o.measure = CheckMeasure::distortion;
  o.worst = 25;  // more than the JSON's 10
  check_both_modes(mesh, o, path);
}

INSTANTIATE_TEST_SUITE_P(CuratedMeshes, CheckStreamShared,
                         testing::Values("hex_box_N20_amp0.35_seed777", "mixed_h0.6_o2", "quad_h0.4_o2",
                                         "tets_h0.8_o2", "tri_h0.4_o4", "warped_hexahedron_o2_N6_a0.25",
                                         "warped_prism_o2_N6_a0.25", "warped_pyramid_o1_N6_a0.1",
                                         "warped_pyramid_o2_N6_a0.15", "warped_tetrahedron_o3_N6_a0.25"));

// Several blocks: many linear quadrangles (more than one batch), curved triangles, a type
// not analysed (skipped), and lines (of a lower dimension: not analysed, NaN
// in the fields).
Mesh random_mixed_mesh(std::size_t quads, unsigned seed) {
  std::mt19937 rng(seed);
  Mesh mesh;
  const auto add_elements = [&](const ElementType& type, const std::vector<std::vector<double>>& elements) {
    Mesh part = test::mesh_of_elements(type, elements);
    ElementBlock b = std::move(part.blocks[0]);
    const auto shift = static_cast<NodeIndex>(mesh.node_tags.size());
    for (NodeIndex& n : b.nodes) n += shift;
    for (Tag& t : b.tags) t += 1000000 * (mesh.blocks.size() + 1);
    for (std::size_t i = 0; i < part.node_tags.size(); ++i) mesh.node_tags.push_back(mesh.node_tags.size() + 1);
    mesh.coords.insert(mesh.coords.end(), part.coords.begin(), part.coords.end());
    mesh.blocks.push_back(std::move(b));
  };
  const auto add_block = [&](const ElementType& type, std::size_t count, double amplitude) {
    std::vector<std::vector<double>> elements;
    for (std::size_t e = 0; e < count; ++e) elements.push_back(test::random_element(type, amplitude, rng));
    add_elements(type, elements);
  };
  add_block(*find_element_type(ElementFamily::line, 2, true), 40, 0.1);
  add_block(*find_element_type(ElementFamily::quadrangle, 1, true), quads, 0.3);
  add_block(*find_element_type(ElementFamily::triangle, 2, true), 300, 0.2);
  // Three elements of a 2D type not analysed (every Lagrange triangle and quadrangle is):
  // Gmsh's 4-node "Triangle Mini", a linear triangle and its bubble node.
  {
    const ElementType& mini = *find_element_type(138);
    const ElementType& linear = *find_element_type(ElementFamily::triangle, 1, true);
    std::vector<std::vector<double>> elements;
    for (int e = 0; e < 3; ++e) {
      std::vector<double> x = test::random_element(linear, 0.0, rng);
      for (int j = 0; j < 3; ++j) x.push_back((x[j] + x[3 + j] + x[6 + j]) / 3);
      elements.push_back(std::move(x));
    }
    add_elements(mini, elements);
  }
  add_block(*find_element_type(ElementFamily::quadrangle, 2, true), 200, 0.25);
  return mesh;
}

TEST(CheckStream, RandomMeshesAcrossBatches) {
  const Mesh mesh = random_mixed_mesh(kCheckBatch + 3000, 7);
  CheckOptions o;
  o.worst = 12;
  const StreamedRun run = streamed_run(mesh, o, "random");
  // Batches are runs of whole chunks: the quadrangles fill the first, their last 3000 and
  // the other blocks share the second.
  EXPECT_EQ(run.batches, 2u);
  EXPECT_EQ(run.summary.skipped(), 3u);  // the Triangle Mini elements
  EXPECT_GT(run.summary.count(Validity::invalid), 0u);
  EXPECT_GT(run.summary.count(Validity::valid), 0u);
  check_both_modes(mesh, o, "random");
}

TEST(CheckStream, RandomMeshMeasuringMuAndScaledJacobian) {
  const Mesh mesh = random_mixed_mesh(500, 8);
  CheckOptions o;
  o.measure = CheckMeasure::all;
  const StreamedRun run = streamed_run(mesh, o, "random");
  EXPECT_GT(run.summary.mu.counts.computed, 0u);
  EXPECT_GT(run.summary.sj.counts.computed, 0u);
  check_both_modes(mesh, o, "random");
}

TEST(CheckStream, WorstListKeepsTheLowestWhateverTheOrder) {
  // Brute force on shuffled streams with ties and NaN keys.
  std::mt19937 rng(3);
  std::vector<WorstElement> all;
  for (std::size_t i = 0; i < 500; ++i) {
    WorstElement e;
    e.index = i;
    e.tag = 1 + rng() % 50;  // repeated tags
    e.key = i % 37 == 0 ? std::nan("") : static_cast<double>(rng() % 20) / 10;  // ties
    all.push_back(e);
  }
  const auto before = [](const WorstElement& a, const WorstElement& b) {
    const double ka = std::isnan(a.key) ? -INFINITY : a.key, kb = std::isnan(b.key) ? -INFINITY : b.key;
    return ka != kb ? ka < kb : a.tag != b.tag ? a.tag < b.tag : a.index < b.index;
  };
  std::vector<WorstElement> want = all;
  std::sort(want.begin(), want.end(), before);
  want.resize(15);
  for (int trial = 0; trial < 5; ++trial) {
    std::shuffle(all.begin(), all.end(), rng);
    WorstList list(15), gated(15);  // gated: offered only what may_take lets through
    for (const WorstElement& e : all) {
      list.offer(e);
      if (gated.may_take(e.key)) gated.offer(e);
    }
    for (const WorstList* l : {&list, &gated}) {
      const auto got = l->sorted();
      ASSERT_EQ(got.size(), want.size());
      for (std::size_t k = 0; k < got.size(); ++k) EXPECT_EQ(got[k].index, want[k].index) << k;
    }
  }
  const WorstList none(0);
  EXPECT_FALSE(none.may_take(0.5));
  EXPECT_FALSE(none.may_take(std::nan("")));
}

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(CheckStream, CliFilesEqualTheLibrarys) {
  const std::string mesh_path = std::string(QUADVAL_SHARED_DIR) + "/data/curved/mixed_h0.6_o2.msh";
  const auto dir = std::filesystem::temp_directory_path() / ("quadval_check_stream_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string cmd = std::string(QUADVAL_CLI_PATH) + " check " + mesh_path + " -q --threads 2 --measure distortion -o " +
                          (dir / "a.csv").string() + " -o " + (dir / "a.json").string() + " -o " +
                          (dir / "a.vtu").string() + " > /dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);  // the mesh has invalid elements
  CheckOptions o;
  o.measure = CheckMeasure::distortion;
  const CheckReport stored = check_mesh(read_mesh(mesh_path), o, mesh_path);
  EXPECT_EQ(slurp(dir / "a.csv"), check_csv(stored));  // no timings in the CSV: same bytes
  // The JSON holds timings: equal once they are removed.
  auto got = nlohmann::json::parse(slurp(dir / "a.json"));
  auto want = nlohmann::json::parse(check_json(stored));
  for (auto* j : {&got, &want}) {
    (*j)["summary"].erase("seconds");
    (*j)["summary"].erase("threads");
    for (auto& s : (*j)["summary"]["stages"]) s.erase("cpu_seconds");
  }
  EXPECT_EQ(got, want);
  EXPECT_GT(std::filesystem::file_size(dir / "a.vtu"), 0u);
  std::filesystem::remove_all(dir);
}

// The coordinate checks of one pass (finite, span per axis) and the planar test: a
// non-finite coordinate or a span beyond 1e40 is refused naming the file, wherever it
// sits; a triangle mesh is planar when its triangles' nodes share z, even when a node no
// triangle uses lies elsewhere.
TEST(CheckStream, CoordinateChecksAndPlanarTest) {
  Mesh mesh;
  mesh.node_tags = {1, 2, 3, 4, 5};
  mesh.coords = {0, 0, 2, 1, 0, 2, 0, 1, 2, 1, 1, 2, 5, 5, 7};  // node 5 off the plane
  ElementBlock tris;
  tris.type = find_element_type(2);  // 3-node triangle
  tris.tags = {1, 2};
  tris.nodes = {0, 1, 2, 1, 3, 2};
  mesh.blocks.push_back(tris);
  CheckOptions o;
  EXPECT_TRUE(check_mesh(mesh, o, "m.msh").planar);
  Mesh lifted = mesh;
  lifted.coords[11] = 2.5;  // node 4's z: the triangles no longer share z
  EXPECT_FALSE(check_mesh(lifted, o, "m.msh").planar);
  Mesh flat = mesh;
  flat.coords[14] = 2;  // every node on the plane: the one-pass answer
  EXPECT_TRUE(check_mesh(flat, o, "m.msh").planar);
  for (std::size_t at : {std::size_t{0}, std::size_t{7}, std::size_t{14}})
    for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                       -std::numeric_limits<double>::infinity()}) {
      Mesh m = mesh;
      m.coords[at] = bad;
      try {
        check_mesh(m, o, "bad.msh");
        ADD_FAILURE() << "accepted " << bad << " at " << at;
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("bad.msh"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("not finite"), std::string::npos) << e.what();
      }
    }
  Mesh wide = mesh;
  wide.coords[13] = 2e40;  // node 5's y: a span of 2e40
  EXPECT_THROW(check_mesh(wide, o, "wide.msh"), InputError);
  wide.coords[13] = 5e39;
  EXPECT_NO_THROW(check_mesh(wide, o, "wide.msh"));

  // The pass reads blocks of kNativeLanes triples (4 or 8), then a tail: 45 nodes (whole
  // blocks and 1 or 5 triples), unused nodes added on the plane. Every coordinate, in a
  // block or the tail, is seen, on its own axis.
  Mesh many = mesh;
  many.coords[14] = 2;
  for (int k = 0; k < 40; ++k) {
    many.node_tags.push_back(6 + k);
    many.coords.insert(many.coords.end(), {0.5, 0.5, 2});
  }
  EXPECT_TRUE(check_mesh(many, o, "many.msh").planar);
  for (std::size_t at = 0; at < many.coords.size(); at += 1) {
    Mesh m = many;
    m.coords[at] = std::numeric_limits<double>::infinity();
    EXPECT_THROW(check_mesh(m, o, "bad.msh"), InputError) << "infinity at " << at;
    m.coords[at] = 3e40;  // a span beyond 1e40 on that axis alone
    EXPECT_THROW(check_mesh(m, o, "wide.msh"), InputError) << "3e40 at " << at;
    m.coords[at] = at % 3 == 2 ? 2 : 0.5;
    EXPECT_NO_THROW(check_mesh(m, o, "fine.msh")) << at;
  }
}

}  // namespace
}  // namespace quadval
