// OBJ read in runs of lines on several threads (read_obj with runs > 1): the same mesh,
// warnings and errors as the whole file read at once, on a generated file with every form the
// reader accepts (relative indices across runs, slashes, comments, CR LF, tabs, ignored and
// unknown statements), at errors placed in later runs, and on randomly mutated copies.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "io/surface_read.hpp"
#include "quadval/error.hpp"

namespace quadval {
namespace {

using ::testing::HasSubstr;

// A grid of nx x ny vertices, written row by row, each row followed by the faces of the cells
// below it (quads and, in every third row, two triangles per cell), by absolute and by
// relative indices in turn; comments, blank lines, CR LF, tabs, texture and group statements,
// and two unknown statements ("curv" and "cstype", each used several times) in between.
struct GeneratedObj {
  std::string text;
  std::size_t vertices = 0, triangles = 0, quads = 0;
  std::vector<long> unknown_first_lines;  // "curv", then "cstype"
  std::array<NodeIndex, 4> first_quad{};  // the nodes of the file's first quad (0-based)
};

GeneratedObj generate(int nx, int ny) {
  GeneratedObj g;
  long line = 0;
  const auto put = [&](const std::string& s) {
    g.text += s;
    ++line;
  };
  put("# generated grid\n");
  put("mtllib grid.mtl\n");
  bool quad_seen = false;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const double x = i * 0.125, y = j * 0.0625 - 1.0, z = (i * j % 7) * 1e-3;
      if (j % 4 == 1)
        put(fmt::format("v\t{}  {} {}\r\n", x, y, z));
      else if (i % 5 == 0)
        put(fmt::format("v {} {} {} 1.0\n", x, y, z));
      else
        put(fmt::format("v {} {} {}\n", x, y, z));
      ++g.vertices;
    }
    if (j % 5 == 2) put("\n");
    if (j % 7 == 3) put("vt 0.5 0.5 # texture\n");
    if (j % 11 == 5) put("g row\n");
    if (j % 13 == 6) {
      if (g.unknown_first_lines.empty()) g.unknown_first_lines.push_back(line + 1);
      put("curv 0 1 1 2\n");
    }
    if (j == ny / 2 || j == ny - 2) {
      if (g.unknown_first_lines.size() == 1) g.unknown_first_lines.push_back(line + 1);
      put("cstype bspline\n");
    }
    if (j == 0) continue;
    for (int i = 0; i + 1 < nx; ++i) {
      // Cell (i, j-1)-(i+1, j): corners a b (row j-1), c d (row j), 1-based.
      const std::int64_t a = std::int64_t{j - 1} * nx + i + 1, b = a + 1, d = a + nx, c = d + 1;
      const auto ref = [&](std::int64_t v) {
        const std::int64_t rel = v - static_cast<std::int64_t>(g.vertices) - 1;  // negative
        return (i + j) % 2 == 0 ? fmt::format("{}", v) : fmt::format("{}", rel);
      };
      if (j % 3 == 0) {
        put(fmt::format("f {} {} {}\n", ref(a), ref(b), ref(c)));
        put(fmt::format("f {}/1 {}/1/1 {}//1\n", ref(a), ref(c), ref(d)));
        g.triangles += 2;
      } else {
        put(fmt::format("f {} {}/2 {} {}  # cell\n", ref(a), ref(b), ref(c), ref(d)));
        if (!quad_seen) {
          g.first_quad = {static_cast<NodeIndex>(a - 1), static_cast<NodeIndex>(b - 1), static_cast<NodeIndex>(c - 1),
                          static_cast<NodeIndex>(d - 1)};
          quad_seen = true;
        }
        ++g.quads;
      }
    }
  }
  return g;
}

struct Outcome {
  Mesh mesh;
  std::vector<std::string> warnings;
  std::string error;  // empty when read
  std::size_t runs_used = 0;
};

Outcome read_in_runs(const std::string& text, std::size_t runs) {
  Outcome o;
  try {
    o.mesh = io::read_obj(text, "g.obj", o.warnings, runs, &o.runs_used);
  } catch (const InputError& e) {
    o.error = e.what();
  }
  return o;
}

void expect_same(const Outcome& a, const Outcome& b) {
  EXPECT_EQ(a.error, b.error);
  EXPECT_EQ(a.warnings, b.warnings);
  EXPECT_EQ(a.mesh.coords, b.mesh.coords);
  EXPECT_EQ(a.mesh.node_tags, b.mesh.node_tags);
  ASSERT_EQ(a.mesh.blocks.size(), b.mesh.blocks.size());
  for (std::size_t k = 0; k < a.mesh.blocks.size(); ++k) {
    EXPECT_EQ(a.mesh.blocks[k].type, b.mesh.blocks[k].type);
    EXPECT_EQ(a.mesh.blocks[k].tags, b.mesh.blocks[k].tags);
    EXPECT_EQ(a.mesh.blocks[k].nodes, b.mesh.blocks[k].nodes);
  }
}

TEST(ObjRuns, SameMeshAndWarningsInAnyNumberOfRuns) {
  const GeneratedObj g = generate(40, 60);
  const Outcome whole = read_in_runs(g.text, 1);
  ASSERT_EQ(whole.error, "");
  // The generator's own counts and first quad.
  EXPECT_EQ(whole.mesh.num_nodes(), g.vertices);
  ASSERT_EQ(whole.mesh.blocks.size(), 2u);
  EXPECT_EQ(whole.mesh.blocks[0].size(), g.triangles);
  EXPECT_EQ(whole.mesh.blocks[1].size(), g.quads);
  EXPECT_EQ((std::array<NodeIndex, 4>{whole.mesh.blocks[1].nodes[0], whole.mesh.blocks[1].nodes[1],
                                      whole.mesh.blocks[1].nodes[2], whole.mesh.blocks[1].nodes[3]}),
            g.first_quad);
  EXPECT_EQ(whole.mesh.coords[3 * 41], 0.125);  // vertex (1, 1)
  EXPECT_EQ(whole.mesh.coords[3 * 41 + 1], -0.9375);
  ASSERT_EQ(whole.warnings.size(), 2u);
  EXPECT_THAT(whole.warnings[0], HasSubstr(fmt::format("g.obj:{}: OBJ statement 'curv'", g.unknown_first_lines[0])));
  EXPECT_THAT(whole.warnings[1], HasSubstr(fmt::format("g.obj:{}: OBJ statement 'cstype'", g.unknown_first_lines[1])));
  for (std::size_t runs = 2; runs <= 7; ++runs) {
    SCOPED_TRACE(fmt::format("{} runs", runs));
    const Outcome parts = read_in_runs(g.text, runs);
    EXPECT_EQ(parts.runs_used, runs);  // relative indices reach back into earlier runs
    expect_same(parts, whole);
  }
}

// Over 1 MiB, the public reader takes the runs (on the threads there are): the same again.
TEST(ObjRuns, LargeFileThroughThePublicReader) {
  const GeneratedObj g = generate(150, 220);
  ASSERT_GT(g.text.size(), std::size_t{1} << 20);
  Outcome pub;
  pub.mesh = io::read_obj(g.text, "g.obj", pub.warnings);
  expect_same(pub, read_in_runs(g.text, 1));
}

// Errors in later runs: the message and line of the whole-file read, the first in the file
// where there are two.
TEST(ObjRuns, ErrorsInLaterRunsAsInTheWholeFile) {
  const GeneratedObj g = generate(40, 60);
  std::vector<std::string> lines;
  for (std::size_t at = 0; at < g.text.size();) {
    const std::size_t end = g.text.find('\n', at);
    lines.push_back(g.text.substr(at, end - at + 1));
    at = end + 1;
  }
  // The lines inserted before lines[i] (each new line is then line i + 1; edits in
  // decreasing i, so that the later ones do not move the earlier).
  const auto with = [&](std::vector<std::pair<std::size_t, std::string>> edits) {
    std::vector<std::string> l = lines;
    for (auto& [i, s] : edits) l.insert(l.begin() + static_cast<std::ptrdiff_t>(i), s);
    std::string t;
    for (const auto& s : l) t += s;
    return t;
  };
  const std::size_t late = lines.size() * 3 / 4, later = lines.size() * 7 / 8;
  const struct {
    std::string text;
    std::string message;
  } cases[] = {
      {with({{late, "v 0 nan 0\n"}}), fmt::format("g.obj:{}: vertex y coordinate is 'nan'", late + 1)},
      {with({{late, "f 1 0 2\n"}}), fmt::format("g.obj:{}: vertex index 0", late + 1)},
      {with({{late, "f 1 2 3 4 5\n"}}), fmt::format("g.obj:{}: face with 5 vertices", late + 1)},
      // Relative: fine against the whole file's vertices, before the first one past them.
      {with({{late, "f -1200 -1 -2\n"}}), ""},
      {with({{late, "f 1 -1 2/3/4\n"}, {late, "f -2 -3 1\n"}}), ""},
      {with({{late, "f -1 -2 -999999\n"}}),
       fmt::format("g.obj:{}: relative vertex index -999999 points before the first vertex", late + 1)},
      {with({{late, "f 1 2 999999\n"}}), fmt::format("g.obj:{}: face refers to vertex 999999, the file has {}", late + 1, g.vertices)},
      {with({{later, "f 1 0 2\n"}, {late, "v 1 2\n"}}), fmt::format("g.obj:{}: expected 'v x y z'", late + 1)},
      {with({{later, "v 1 2\n"}, {late, "f 1 2 3 4 5 6\n"}}), fmt::format("g.obj:{}: face with 6 vertices", late + 1)},
      // An error past a line the runs may cut at: the runs' line numbers add up.
      {with({{lines.size() / 2, "v 1 1 inf\n"}}), fmt::format("g.obj:{}: vertex z coordinate is 'inf'", lines.size() / 2 + 1)},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.message);
    const Outcome whole = read_in_runs(c.text, 1);
    if (c.message.empty())
      EXPECT_EQ(whole.error, "");
    else
      EXPECT_THAT(whole.error, HasSubstr(c.message));
    for (std::size_t runs : {2u, 3u, 5u}) {
      const Outcome parts = read_in_runs(c.text, runs);
      if (c.message.empty()) EXPECT_EQ(parts.runs_used, runs);
      expect_same(parts, whole);
    }
  }
}

// Random edits (a byte changed, removed or inserted; a line end removed or added) of a
// smaller file: every outcome, read or error, is the whole file's.
TEST(ObjRuns, MutatedFilesAsTheWholeFile) {
  const GeneratedObj g = generate(12, 16);
  std::mt19937 rng(11);
  const std::string alphabet = "0123456789 -+./#\n\r\tfvnxe";
  int errors = 0, read = 0;
  for (int trial = 0; trial < 400; ++trial) {
    std::string t = g.text;
    const int edits = 1 + trial % 3;
    for (int e = 0; e < edits; ++e) {
      const std::size_t at = std::uniform_int_distribution<std::size_t>(0, t.size() - 1)(rng);
      const char c = alphabet[std::uniform_int_distribution<std::size_t>(0, alphabet.size() - 1)(rng)];
      switch (trial % 4) {
        case 0: t[at] = c; break;
        case 1: t.erase(at, 1); break;
        case 2: t.insert(at, 1, c); break;
        default: t[at] = t[at] == '\n' ? ' ' : '\n'; break;
      }
    }
    const Outcome whole = read_in_runs(t, 1);
    (whole.error.empty() ? read : errors)++;
    for (std::size_t runs : {2u, 3u, 4u}) {
      SCOPED_TRACE(fmt::format("trial {}, {} runs", trial, runs));
      expect_same(read_in_runs(t, runs), whole);
    }
  }
  EXPECT_GT(errors, 50);
  EXPECT_GT(read, 50);
}

}  // namespace
}  // namespace quadval
