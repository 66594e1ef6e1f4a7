#pragma once
/// A planar domain for people without a CAD file: an outer boundary (polygon, rectangle or
/// circle) with holes, read from a small text format:
///
///     # the square with a hole of Paper I §8.1
///     outer rectangle 0 0 1 1          # x0 y0 x1 y1
///     hole circle 0.75 0.75 0.15       # cx cy r
///     hole polygon 0.2 0.2  0.4 0.2  0.3 0.35
///
/// One statement per line; on the command line, statements may be separated by ';'.
/// '#' starts a comment. Keywords: `outer` or `hole`, then `polygon x1 y1 x2 y2 ...`
/// (at least 3 vertices, either orientation, not closed by repeating the first vertex),
/// `rectangle x0 y0 x1 y1` (x0 < x1, y0 < y1) or `circle cx cy r` (r > 0).
/// Exactly one `outer`. Polygons must be simple; holes must lie strictly inside the outer
/// boundary and must not touch each other.

#include <array>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace quadval {

/// One closed boundary curve of a planar domain.
struct DomainLoop {
  enum class Kind { polygon, circle };
  Kind kind = Kind::polygon;
  std::vector<std::array<double, 2>> vertices;  ///< polygon: #vertices ≥ 3, counterclockwise
  std::array<double, 2> center{};               ///< circle
  double radius = 0.0;                          ///< circle
  int line = 0;                                 ///< statement number in the source (1-based)
};

struct PlanarDomain {
  DomainLoop outer;
  std::vector<DomainLoop> holes;
  std::string source;  ///< file name or "<command line>", for messages
};

/// Parses the text format above. `source` names the text in messages. Throws InputError
/// "SOURCE:LINE: ..." on a bad statement, a non-simple polygon, a hole that is not strictly
/// inside the outer boundary, or holes that touch.
PlanarDomain parse_planar_domain(std::string_view text, const std::string& source);

/// Reads and parses a file. Throws InputError if it cannot be read.
PlanarDomain read_planar_domain(const std::filesystem::path& path);

/// Distance from (x, y) to the nearest boundary curve (outer or hole); exact for polygons
/// and circles.
double distance_to_boundary(const PlanarDomain& domain, double x, double y);

/// True if (x, y) is inside the outer boundary and outside every hole (boundary included).
bool domain_contains(const PlanarDomain& domain, double x, double y);

/// Area of the domain: outer area minus the holes' areas (exact: shoelace and pi r^2).
double domain_area(const PlanarDomain& domain);

/// Bounding box of the outer boundary: minX minY minZ maxX maxY maxZ, with z = 0.
std::array<double, 6> domain_bounding_box(const PlanarDomain& domain);

}  // namespace quadval
