#include "quadval/svg.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

namespace quadval {
namespace {

using testing::HasSubstr;

// Two unit squares side by side, x in [0, 2], y in [0, 1], plus one boundary line element
// (which must not be drawn but still takes a value slot).
Mesh two_quads() {
  Mesh m;
  m.node_tags = {1, 2, 3, 4, 5, 6};
  m.coords = {0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0, 1, 1, 0, 2, 1, 0};
  ElementBlock line;
  line.type = find_element_type(1);
  line.tags = {1};
  line.nodes = {0, 1};
  ElementBlock quads;
  quads.type = find_element_type(3);
  quads.tags = {2, 3};
  quads.nodes = {0, 1, 4, 3, 1, 2, 5, 4};
  m.blocks = {line, quads};
  return m;
}

std::vector<std::string> all_matches(const std::string& text, const std::string& pattern) {
  std::vector<std::string> out;
  const std::regex re(pattern);
  for (auto it = std::sregex_iterator(text.begin(), text.end(), re); it != std::sregex_iterator(); ++it)
    out.push_back((*it)[1]);
  return out;
}

TEST(Svg, ColourMapEndsAndMiddleAreViridis) {
  // Published viridis samples: #440154 at 0, #26828e at 0.5, #fde725 at 1.
  EXPECT_EQ(colour_map(0.0), (std::array<unsigned char, 3>{0x44, 0x01, 0x54}));
  EXPECT_EQ(colour_map(0.5), (std::array<unsigned char, 3>{0x26, 0x82, 0x8e}));
  EXPECT_EQ(colour_map(1.0), (std::array<unsigned char, 3>{0xfd, 0xe7, 0x25}));
  EXPECT_EQ(colour_map(-3.0), colour_map(0.0));  // clamped
  EXPECT_EQ(colour_map(7.0), colour_map(1.0));
  EXPECT_EQ(colour_map(std::nan("")), (std::array<unsigned char, 3>{160, 160, 160}));
  // Halfway between the samples at 7/8 (#6ece58) and 1 (#fde725), rounded.
  EXPECT_EQ(colour_map(15.0 / 16.0), (std::array<unsigned char, 3>{182, 219, 63}));
}

TEST(Svg, MeshPictureHasOnePolygonPerSurfaceElementWithItsColour) {
  const Mesh m = two_quads();
  const std::vector<double> values{99.0 /* the line: not drawn */, 0.0, 1.0};
  MeshSvgOptions o;
  o.title = "eta <quads> & more";
  o.value_name = "eta";
  o.width = 400;
  const std::string svg = mesh_svg(m, values, o);
  const auto fills = all_matches(svg, "<polygon points=\"[^\"]*\" fill=\"([^\"]*)\"");
  ASSERT_EQ(fills.size(), 2u);
  EXPECT_EQ(fills[0], "rgb(68,1,84)");     // value 0 -> colour_map(0)
  EXPECT_EQ(fills[1], "rgb(253,231,37)");  // value 1 -> colour_map(1)
  EXPECT_THAT(svg, HasSubstr("eta &lt;quads&gt; &amp; more"));  // escaped title
  // The domain is 2 x 1 and the drawing fits 400 px: scale 200 px per unit. The first quad
  // (0,0) (1,0) (1,1) (0,1) is drawn from the left margin (20) and below the title (34 + 20),
  // y flipped.
  const auto points = all_matches(svg, "<polygon points=\"([^\"]*)\"");
  EXPECT_EQ(points[0], "20.00,254.00 220.00,254.00 220.00,54.00 20.00,54.00");
  // The colour bar labels its ends with the range.
  EXPECT_THAT(svg, HasSubstr(">0</text>"));
  EXPECT_THAT(svg, HasSubstr(">1</text>"));
  EXPECT_THAT(svg, HasSubstr("</svg>"));
}

TEST(Svg, SurfaceIn3DIsDrawnFarthestFirst) {
  // Two triangles, one at z = 0 and one at z = 5 above it: the higher one is nearer to a
  // viewer at (1, 1, 1) * infinity and must be drawn last.
  Mesh m;
  m.node_tags = {1, 2, 3, 4, 5, 6};
  m.coords = {0, 0, 5, 1, 0, 5, 0, 1, 5, 0, 0, 0, 1, 0, 0, 0, 1, 0};
  ElementBlock t;
  t.type = find_element_type(2);
  t.tags = {1, 2};
  t.nodes = {0, 1, 2, 3, 4, 5};
  m.blocks = {t};
  const std::string svg = mesh_svg(m, std::vector<double>{1.0, 0.0}, {});
  const auto fills = all_matches(svg, "<polygon points=\"[^\"]*\" fill=\"([^\"]*)\"");
  ASSERT_EQ(fills.size(), 2u);
  EXPECT_EQ(fills[0], "rgb(68,1,84)");     // the z = 0 triangle (value 0) first
  EXPECT_EQ(fills[1], "rgb(253,231,37)");  // then the z = 5 one
}

TEST(Svg, HistogramCountsFollowTheBinRule) {
  const std::vector<double> v{-1.0, 0.0, 0.09, 0.1, 0.5, 0.99, 1.0, 3.0, std::nan("")};
  // 10 bins on [0, 1]: -1 and 0 and 0.09 in bin 0; 0.1 in bin 1; 0.5 in bin 5; 0.99, 1, 3 in
  // bin 9; NaN nowhere.
  const std::vector<std::size_t> want{3, 1, 0, 0, 0, 1, 0, 0, 0, 3};
  EXPECT_EQ(histogram_counts(v, 0.0, 1.0, 10), want);
}

TEST(Svg, HistogramBarsMatchABruteForceCount) {
  std::vector<double> v;
  for (int i = 0; i < 1000; ++i) v.push_back(std::fmod(i * 0.618034, 1.0));
  HistogramSvgOptions o;
  o.title = "eta";
  o.x_label = "eta";
  o.bins = 8;
  o.markers = {{0.5, "half"}};
  const std::string svg = histogram_svg(v, o);
  const auto counts = all_matches(svg, "data-count=\"([0-9]+)\"");
  ASSERT_EQ(counts.size(), 8u);
  for (int b = 0; b < 8; ++b) {
    std::size_t brute = 0;
    for (double x : v) brute += (x >= b / 8.0 && x < (b + 1) / 8.0);
    EXPECT_EQ(std::stoul(counts[b]), brute) << "bin " << b;
  }
  EXPECT_THAT(svg, HasSubstr("n = 1000"));
  EXPECT_THAT(svg, HasSubstr(">half</text>"));
}

TEST(Svg, HistogramSaysWhatWasClampedAndWritesAtomically) {
  const std::vector<double> v{0.5, 2.5, 3.0, -0.5};
  HistogramSvgOptions o;
  o.lo = 0;
  o.hi = 2;
  o.bins = 4;
  const std::string svg = histogram_svg(v, o);
  EXPECT_THAT(svg, HasSubstr("1 below 0 in the first bar"));
  EXPECT_THAT(svg, HasSubstr("2 above 2 in the last bar"));
  const auto dir = std::filesystem::temp_directory_path() / "quadval_svg_test";
  std::filesystem::create_directories(dir);
  write_histogram_svg(v, dir / "h.svg", o);
  std::ifstream in(dir / "h.svg");
  std::stringstream s;
  s << in.rdbuf();
  EXPECT_EQ(s.str(), svg);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace quadval
