#pragma once
// Helpers shared by the SVG writers (svg_mesh.cpp, svg_histogram.cpp). Internal to src/io.

#include <string>
#include <string_view>

namespace quadval::svg_detail {

/// Text safe inside an XML element or attribute: & < > " ' escaped.
std::string escape(std::string_view text);

/// The opening <svg> tag with a white background, and the closing tag.
std::string begin_document(double width, double height);
inline constexpr std::string_view kEndDocument = "</svg>\n";

/// <text> at (x, y); anchor "start", "middle" or "end".
std::string text(double x, double y, std::string_view content, double size = 14,
                 std::string_view anchor = "start", std::string_view extra = "");

/// Compact decimal for labels: up to 3 significant digits after trimming (0.5, 12.3, 1e-05).
std::string label_number(double v);

}  // namespace quadval::svg_detail
