// A surface mesh as an SVG picture, coloured by one value per element, with a colour bar.
#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/core.h>

#include "io/svg_common.hpp"
#include "quadval/atomic_file.hpp"
#include "quadval/error.hpp"
#include "quadval/svg.hpp"

namespace quadval {

std::array<unsigned char, 3> colour_map(double t) noexcept {
  // viridis (matplotlib) at t = 0, 1/8, ..., 1.
  static constexpr unsigned char kSamples[9][3] = {
      {68, 1, 84},   {72, 40, 120},  {62, 73, 137}, {49, 104, 142}, {38, 130, 142},
      {31, 158, 137}, {53, 183, 121}, {110, 206, 88}, {253, 231, 37}};
  if (std::isnan(t)) return {160, 160, 160};
  t = std::clamp(t, 0.0, 1.0) * 8.0;
  const int i = std::min(static_cast<int>(t), 7);
  const double f = t - i;
  std::array<unsigned char, 3> c{};
  for (int k = 0; k < 3; ++k)
    c[k] = static_cast<unsigned char>(
        std::lround((1.0 - f) * kSamples[i][k] + f * kSamples[i + 1][k]));
  return c;
}

namespace {

using svg_detail::label_number;
using svg_detail::text;

struct Drawn {
  std::vector<std::array<double, 2>> corners;  // projected, model units
  double depth = 0;
  double value = 0;
};

}  // namespace

std::string mesh_svg(const Mesh& mesh, std::span<const double> values,
                     const MeshSvgOptions& options) {
  QV_ASSERT(values.size() == mesh.num_elements(),
            values.size() << " values for " << mesh.num_elements() << " elements");
  QV_ASSERT(options.value_max > options.value_min, "range " << options.value_min << " "
                                                            << options.value_max);
  // Planar in z: draw (x, y). Otherwise an isometric view along -(1,1,1): right = (-1,1,0)/√2,
  // up = (-1,-1,2)/√6, depth = (1,1,1)·p/√3 (larger is nearer, drawn later).
  bool planar = true;
  for (std::size_t i = 0; i < mesh.num_nodes(); ++i)
    if (mesh.coords[3 * i + 2] != mesh.coords[2]) planar = false;
  auto project = [&](NodeIndex n) -> std::array<double, 3> {
    const auto p = mesh.node(n);
    if (planar) return {p[0], p[1], 0.0};
    return {(p[1] - p[0]) / std::sqrt(2.0), (2 * p[2] - p[0] - p[1]) / std::sqrt(6.0),
            (p[0] + p[1] + p[2]) / std::sqrt(3.0)};
  };

  std::vector<Drawn> drawn;
  std::size_t v = 0;
  for (const ElementBlock& block : mesh.blocks) {
    const bool surface = block.type->dim == 2 &&
                         (block.type->family == ElementFamily::triangle ||
                          block.type->family == ElementFamily::quadrangle);
    const int corners = family_num_vertices(block.type->family);
    for (std::size_t e = 0; e < block.size(); ++e, ++v) {
      if (!surface) continue;
      Drawn d;
      d.value = values[v];
      for (int k = 0; k < corners; ++k) {
        const auto q = project(block.element(e)[k]);
        d.corners.push_back({q[0], q[1]});
        d.depth += q[2] / corners;
      }
      drawn.push_back(std::move(d));
    }
  }
  if (!planar)
    std::stable_sort(drawn.begin(), drawn.end(),
                     [](const Drawn& a, const Drawn& b) { return a.depth < b.depth; });

  double lo[2] = {HUGE_VAL, HUGE_VAL}, hi[2] = {-HUGE_VAL, -HUGE_VAL};
  for (const Drawn& d : drawn)
    for (const auto& c : d.corners)
      for (int k = 0; k < 2; ++k) lo[k] = std::min(lo[k], c[k]), hi[k] = std::max(hi[k], c[k]);
  if (drawn.empty()) lo[0] = lo[1] = 0, hi[0] = hi[1] = 1;
  const double dx = std::max(hi[0] - lo[0], 1e-300), dy = std::max(hi[1] - lo[1], 1e-300);
  // Fit in width × width (a tall domain gets narrower, not taller than wide).
  const double box = options.width;
  const double scale = std::min(box / dx, box / dy);
  const double draw_w = dx * scale, draw_h = dy * scale;
  const double margin = 20, title_h = options.title.empty() ? 0 : 34;
  const double bar_x = margin + draw_w + 30, bar_w = 22, bar_h = std::max(draw_h, 200.0);
  // Wide enough for the title too (about 0.6 em per character of an 18 px sans-serif font).
  const double total_w = std::max(bar_x + bar_w + 70, 2 * margin + 0.6 * 18 * options.title.size());
  const double total_h = title_h + margin + bar_h + margin + 10;
  const double x0 = margin, y0 = title_h + margin;

  std::string out = svg_detail::begin_document(total_w, total_h);
  if (!options.title.empty()) out += text(margin, 24, options.title, 18, "start", "font-weight=\"bold\"");
  const double stroke = drawn.size() < 3000 ? 0.6 : drawn.size() < 30000 ? 0.3 : 0.1;
  out += fmt::format("<g id=\"mesh\" stroke=\"{}\" stroke-width=\"{}\" stroke-linejoin=\"round\">\n",
                     options.draw_edges ? "#222" : "none", stroke);
  const double range = options.value_max - options.value_min;
  for (const Drawn& d : drawn) {
    const auto c = colour_map((d.value - options.value_min) / range);
    out += "<polygon points=\"";
    for (std::size_t k = 0; k < d.corners.size(); ++k)
      out += fmt::format("{}{:.2f},{:.2f}", k ? " " : "", x0 + (d.corners[k][0] - lo[0]) * scale,
                         y0 + (hi[1] - d.corners[k][1]) * scale);  // SVG y points down
    out += fmt::format("\" fill=\"rgb({},{},{})\"/>\n", c[0], c[1], c[2]);
  }
  out += "</g>\n";

  // Colour bar: 64 bands from value_min (bottom) to value_max (top), 5 labelled ticks.
  out += "<g id=\"colour-bar\">\n";
  constexpr int kBands = 64;
  for (int i = 0; i < kBands; ++i) {
    const auto c = colour_map((i + 0.5) / kBands);
    out += fmt::format(
        "<rect x=\"{:.1f}\" y=\"{:.2f}\" width=\"{}\" height=\"{:.2f}\" fill=\"rgb({},{},{})\"/>\n",
        bar_x, y0 + bar_h * (1.0 - (i + 1.0) / kBands), bar_w, bar_h / kBands + 0.3, c[0], c[1],
        c[2]);
  }
  out += fmt::format("<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{}\" height=\"{:.1f}\" fill=\"none\" "
                     "stroke=\"#222\"/>\n",
                     bar_x, y0, bar_w, bar_h);
  for (int i = 0; i <= 4; ++i) {
    const double y = y0 + bar_h * (1.0 - i / 4.0);
    out += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#222\"/>\n",
                       bar_x + bar_w, y, bar_x + bar_w + 5, y);
    out += text(bar_x + bar_w + 8, y + 5, label_number(options.value_min + range * i / 4.0), 13);
  }
  out += text(bar_x + bar_w / 2, y0 - 6, options.value_name, 14, "middle");
  out += "</g>\n";
  out += svg_detail::kEndDocument;
  return out;
}

void write_mesh_svg(const Mesh& mesh, std::span<const double> values,
                    const std::filesystem::path& path, const MeshSvgOptions& options) {
  const std::string svg = mesh_svg(mesh, values, options);
  write_file_atomically(path, [&](std::ostream& os) { os << svg; });
}

}  // namespace quadval
