// Histograms as SVG pictures (Paper I Fig. 15: eta and the normalized edge length l^h).
#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "io/svg_common.hpp"
#include "quadval/atomic_file.hpp"
#include "quadval/error.hpp"
#include "quadval/svg.hpp"

namespace quadval {

using svg_detail::label_number;
using svg_detail::text;

std::vector<std::size_t> histogram_counts(std::span<const double> values, double lo, double hi,
                                          int bins) {
  QV_ASSERT(lo < hi && bins >= 1, "range " << lo << " " << hi << ", bins " << bins);
  std::vector<std::size_t> counts(static_cast<std::size_t>(bins), 0);
  for (double v : values) {
    if (std::isnan(v)) continue;
    const double t = std::floor((v - lo) / (hi - lo) * bins);
    const int i = t < 0 ? 0 : t >= bins ? bins - 1 : static_cast<int>(t);
    ++counts[static_cast<std::size_t>(i)];
  }
  return counts;
}

std::string histogram_svg(std::span<const double> values, const HistogramSvgOptions& o) {
  const auto counts = histogram_counts(values, o.lo, o.hi, o.bins);
  std::size_t n = 0, below = 0, above = 0;
  double sum = 0, vmin = HUGE_VAL, vmax = -HUGE_VAL;
  for (double v : values) {
    if (std::isnan(v)) continue;
    ++n;
    sum += v;
    vmin = std::min(vmin, v);
    vmax = std::max(vmax, v);
    if (v < o.lo) ++below;
    if (v > o.hi) ++above;
  }
  const std::size_t peak = counts.empty() ? 0 : *std::max_element(counts.begin(), counts.end());
  // Y axis in percent, rounded up to a multiple of 5 above the highest bar.
  const double peak_pct = n ? 100.0 * peak / n : 0;
  const double y_top = std::max(5.0, 5.0 * std::ceil(peak_pct / 5.0 + 1e-12));

  const double left = 60, right = 20, top = 62, bottom = 50;
  const double pw = o.width - left - right, ph = o.height - top - bottom;
  std::string out = svg_detail::begin_document(o.width, o.height);
  out += text(left, 22, o.title, 17, "start", "font-weight=\"bold\"");
  std::string summary =
      n ? fmt::format("n = {}, mean {:.3f}, min {:.3f}, max {:.3f}", n, sum / n, vmin, vmax)
        : std::string("no values");
  if (below) summary += fmt::format("; {} below {} in the first bar", below, label_number(o.lo));
  if (above) summary += fmt::format("; {} above {} in the last bar", above, label_number(o.hi));
  out += text(left, 42, summary, 13);

  auto x_of = [&](double v) { return left + (v - o.lo) / (o.hi - o.lo) * pw; };
  auto y_of = [&](double pct) { return top + ph * (1.0 - pct / y_top); };
  out += "<g id=\"bars\" fill=\"#3e7cb1\" stroke=\"white\" stroke-width=\"0.5\">\n";
  for (int i = 0; i < o.bins; ++i) {
    const double pct = n ? 100.0 * counts[i] / n : 0;
    const double x = x_of(o.lo + (o.hi - o.lo) * i / o.bins);
    const double w = pw / o.bins;
    out += fmt::format(
        "<rect x=\"{:.2f}\" y=\"{:.2f}\" width=\"{:.2f}\" height=\"{:.2f}\" data-count=\"{}\"/>\n",
        x, y_of(pct), w, top + ph - y_of(pct), counts[i]);
  }
  out += "</g>\n";
  // Axes, ticks and labels.
  out += fmt::format("<g id=\"axes\" stroke=\"#222\">\n<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{2:.1f}\" y2=\"{1:.1f}\"/>\n"
                     "<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{3:.1f}\"/>\n</g>\n",
                     left, top + ph, left + pw, top);
  for (int i = 0; i <= 5; ++i) {
    const double v = o.lo + (o.hi - o.lo) * i / 5;
    out += fmt::format("<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\" stroke=\"#222\"/>\n",
                       x_of(v), top + ph, top + ph + 5);
    out += text(x_of(v), top + ph + 20, label_number(v), 12, "middle");
    const double pct = y_top * i / 5;
    out += fmt::format("<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{2:.1f}\" y2=\"{1:.1f}\" stroke=\"#222\"/>\n",
                       left - 5, y_of(pct), left);
    out += text(left - 8, y_of(pct) + 4, label_number(pct) + "%", 12, "end");
  }
  out += text(left + pw / 2, o.height - 10, o.x_label, 14, "middle");
  for (const auto& [v, label] : o.markers) {
    if (v < o.lo || v > o.hi) continue;
    out += fmt::format("<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\" stroke=\"#c0392b\" "
                       "stroke-width=\"1.5\" stroke-dasharray=\"5,3\"/>\n",
                       x_of(v), top + ph, top);
    out += text(x_of(v) + 4, top + 12, label, 12, "start", "fill=\"#c0392b\"");
  }
  out += svg_detail::kEndDocument;
  return out;
}

void write_histogram_svg(std::span<const double> values, const std::filesystem::path& path,
                         const HistogramSvgOptions& options) {
  const std::string svg = histogram_svg(values, options);
  write_file_atomically(path, [&](std::ostream& os) { os << svg; });
}

}  // namespace quadval
