#include "quadval/planar_domain.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>

#include <fmt/core.h>

#include "quadval/error.hpp"

namespace quadval {
namespace {

using P2 = std::array<double, 2>;

// ---- small geometric predicates (double precision: this validates user input, it does
// not certify anything) ----

double cross(const P2& o, const P2& a, const P2& b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

double signed_area(const std::vector<P2>& v) {
  double s = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const P2& a = v[i];
    const P2& b = v[(i + 1) % v.size()];
    s += a[0] * b[1] - b[0] * a[1];
  }
  return 0.5 * s;
}

bool on_segment(const P2& a, const P2& b, const P2& p) {
  return std::min(a[0], b[0]) <= p[0] && p[0] <= std::max(a[0], b[0]) &&
         std::min(a[1], b[1]) <= p[1] && p[1] <= std::max(a[1], b[1]);
}

// Closed segments ab and cd share at least one point.
bool segments_touch(const P2& a, const P2& b, const P2& c, const P2& d) {
  const double d1 = cross(c, d, a), d2 = cross(c, d, b), d3 = cross(a, b, c), d4 = cross(a, b, d);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
    return true;
  return (d1 == 0 && on_segment(c, d, a)) || (d2 == 0 && on_segment(c, d, b)) ||
         (d3 == 0 && on_segment(a, b, c)) || (d4 == 0 && on_segment(a, b, d));
}

double point_segment_distance(const P2& p, const P2& a, const P2& b) {
  const double ux = b[0] - a[0], uy = b[1] - a[1];
  const double len2 = ux * ux + uy * uy;
  double t = len2 > 0 ? ((p[0] - a[0]) * ux + (p[1] - a[1]) * uy) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(p[0] - (a[0] + t * ux), p[1] - (a[1] + t * uy));
}

// Even-odd rule; points on the boundary may go either way (callers test distance first).
bool inside_polygon(const std::vector<P2>& v, const P2& p) {
  bool in = false;
  for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i++) {
    if ((v[i][1] > p[1]) != (v[j][1] > p[1]) &&
        p[0] < (v[j][0] - v[i][0]) * (p[1] - v[i][1]) / (v[j][1] - v[i][1]) + v[i][0])
      in = !in;
  }
  return in;
}

double distance_to_loop(const DomainLoop& loop, const P2& p) {
  if (loop.kind == DomainLoop::Kind::circle)
    return std::abs(std::hypot(p[0] - loop.center[0], p[1] - loop.center[1]) - loop.radius);
  double d = std::numeric_limits<double>::infinity();
  const auto& v = loop.vertices;
  for (std::size_t i = 0; i < v.size(); ++i)
    d = std::min(d, point_segment_distance(p, v[i], v[(i + 1) % v.size()]));
  return d;
}

// Strictly inside the region bounded by `loop` (not on it).
bool strictly_inside(const DomainLoop& loop, const P2& p) {
  if (loop.kind == DomainLoop::Kind::circle)
    return std::hypot(p[0] - loop.center[0], p[1] - loop.center[1]) < loop.radius;
  return distance_to_loop(loop, p) > 0 && inside_polygon(loop.vertices, p);
}

bool polygon_edges_touch(const std::vector<P2>& a, const std::vector<P2>& b) {
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = 0; j < b.size(); ++j)
      if (segments_touch(a[i], a[(i + 1) % a.size()], b[j], b[(j + 1) % b.size()])) return true;
  return false;
}

// `inner` lies strictly inside `outer`, boundaries apart.
bool loop_strictly_inside(const DomainLoop& inner, const DomainLoop& outer) {
  using K = DomainLoop::Kind;
  if (inner.kind == K::circle && outer.kind == K::circle)
    return std::hypot(inner.center[0] - outer.center[0], inner.center[1] - outer.center[1]) +
               inner.radius <
           outer.radius;
  if (inner.kind == K::circle)  // circle in polygon
    return strictly_inside(outer, inner.center) &&
           distance_to_loop(outer, inner.center) > inner.radius;
  // A polygon lies in a disk iff its vertices do (the disk is convex).
  if (outer.kind == K::circle)
    return std::all_of(inner.vertices.begin(), inner.vertices.end(),
                       [&](const P2& p) { return strictly_inside(outer, p); });
  return !polygon_edges_touch(inner.vertices, outer.vertices) &&
         std::all_of(inner.vertices.begin(), inner.vertices.end(),
                     [&](const P2& p) { return strictly_inside(outer, p); });
}

// Two holes neither overlap nor touch.
bool loops_apart(const DomainLoop& a, const DomainLoop& b) {
  using K = DomainLoop::Kind;
  if (a.kind == K::circle && b.kind == K::circle)
    return std::hypot(a.center[0] - b.center[0], a.center[1] - b.center[1]) > a.radius + b.radius;
  if (a.kind == K::circle || b.kind == K::circle) {
    const DomainLoop& c = a.kind == K::circle ? a : b;
    const DomainLoop& p = a.kind == K::circle ? b : a;
    return !strictly_inside(p, c.center) && distance_to_loop(p, c.center) > c.radius;
  }
  return !polygon_edges_touch(a.vertices, b.vertices) &&
         !strictly_inside(a, b.vertices[0]) && !strictly_inside(b, a.vertices[0]);
}

// ---- parsing ----

struct Statement {
  int number = 0;
  std::vector<std::string_view> words;
};

std::vector<Statement> split_statements(std::string_view text) {
  std::vector<Statement> out;
  int number = 0;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find_first_of("\n;", start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(start, end - start);
    ++number;
    if (auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    Statement s{number, {}};
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      std::size_t j = i;
      while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
      if (j > i) s.words.push_back(line.substr(i, j - i));
      i = j;
    }
    if (!s.words.empty()) out.push_back(std::move(s));
    start = end + 1;
  }
  return out;
}

double parse_number(std::string_view word, const std::string& source, int line) {
  double v = 0;
  if (!word.empty() && word[0] == '+') word.remove_prefix(1);
  const auto [ptr, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
  if (ec != std::errc() || ptr != word.data() + word.size() || !std::isfinite(v))
    throw InputError::at_line(source, line,
                              fmt::format("'{}' is not a finite number", std::string(word)));
  return v;
}

DomainLoop parse_loop(const Statement& s, const std::string& source) {
  const auto fail = [&](const std::string& message) {
    return InputError::at_line(source, s.number, message);
  };
  if (s.words.size() < 2)
    throw fail("expected a shape after '" + std::string(s.words[0]) +
               "': polygon, rectangle or circle");
  const std::string_view shape = s.words[1];
  std::vector<double> num;
  for (std::size_t i = 2; i < s.words.size(); ++i)
    num.push_back(parse_number(s.words[i], source, s.number));
  DomainLoop loop;
  loop.line = s.number;
  if (shape == "circle") {
    if (num.size() != 3) throw fail(fmt::format("circle needs cx cy r, got {} numbers", num.size()));
    if (!(num[2] > 0)) throw fail(fmt::format("circle radius {} is not positive", num[2]));
    loop.kind = DomainLoop::Kind::circle;
    loop.center = {num[0], num[1]};
    loop.radius = num[2];
    return loop;
  }
  if (shape == "rectangle") {
    if (num.size() != 4)
      throw fail(fmt::format("rectangle needs x0 y0 x1 y1, got {} numbers", num.size()));
    if (!(num[0] < num[2] && num[1] < num[3]))
      throw fail("rectangle needs x0 < x1 and y0 < y1");
    loop.vertices = {{num[0], num[1]}, {num[2], num[1]}, {num[2], num[3]}, {num[0], num[3]}};
    return loop;
  }
  if (shape != "polygon")
    throw fail("unknown shape '" + std::string(shape) + "'; expected polygon, rectangle or circle");
  if (num.size() % 2 != 0)
    throw fail(fmt::format("polygon needs x y pairs, got {} numbers", num.size()));
  for (std::size_t i = 0; i < num.size(); i += 2) loop.vertices.push_back({num[i], num[i + 1]});
  auto& v = loop.vertices;
  if (v.size() < 3) throw fail(fmt::format("polygon needs at least 3 vertices, got {}", v.size()));
  for (std::size_t i = 0; i < v.size(); ++i)
    if (v[i] == v[(i + 1) % v.size()])
      throw fail(fmt::format("polygon vertices {} and {} coincide (do not repeat the first vertex "
                             "at the end)",
                             i + 1, (i + 1) % v.size() + 1));
  // Simple: non-adjacent sides do not touch; adjacent sides meet only at their shared vertex
  // (they fold back onto each other if collinear and pointing back).
  const std::size_t n = v.size();
  for (std::size_t i = 0; i < n; ++i) {
    const P2 &a = v[i], &b = v[(i + 1) % n], &c = v[(i + 2) % n];
    if (cross(a, b, c) == 0 && ((b[0] - a[0]) * (c[0] - b[0]) + (b[1] - a[1]) * (c[1] - b[1])) < 0)
      throw fail(fmt::format("polygon folds back on itself at vertex {}", (i + 1) % n + 1));
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through the closing side
      if (segments_touch(a, b, v[j], v[(j + 1) % n]))
        throw fail(fmt::format("polygon is not simple: side {} touches side {}", i + 1, j + 1));
    }
  }
  const double area = signed_area(v);
  if (area == 0) throw fail("polygon has zero area");
  if (area < 0) std::reverse(v.begin(), v.end());  // store counterclockwise
  return loop;
}

}  // namespace

PlanarDomain parse_planar_domain(std::string_view text, const std::string& source) {
  PlanarDomain domain;
  domain.source = source;
  bool have_outer = false;
  for (const Statement& s : split_statements(text)) {
    const std::string_view role = s.words[0];
    if (role != "outer" && role != "hole")
      throw InputError::at_line(source, s.number,
                                "unknown statement '" + std::string(role) +
                                    "'; expected 'outer' or 'hole'");
    DomainLoop loop = parse_loop(s, source);
    if (role == "outer") {
      if (have_outer)
        throw InputError::at_line(source, s.number,
                                  fmt::format("second 'outer' (the first is on line {})",
                                              domain.outer.line));
      domain.outer = std::move(loop);
      have_outer = true;
    } else {
      domain.holes.push_back(std::move(loop));
    }
  }
  if (!have_outer)
    throw InputError::in_file(source, "no 'outer' boundary (e.g. 'outer rectangle 0 0 1 1')");
  for (std::size_t i = 0; i < domain.holes.size(); ++i) {
    const DomainLoop& h = domain.holes[i];
    if (!loop_strictly_inside(h, domain.outer))
      throw InputError::at_line(
          source, h.line,
          fmt::format("hole is not strictly inside the outer boundary (line {})", domain.outer.line));
    for (std::size_t j = 0; j < i; ++j)
      if (!loops_apart(h, domain.holes[j]))
        throw InputError::at_line(source, h.line,
                                  fmt::format("hole overlaps or touches the hole on line {}",
                                              domain.holes[j].line));
  }
  return domain;
}

PlanarDomain read_planar_domain(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError::in_file(path.string(), "cannot open the domain file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_planar_domain(text.str(), path.string());
}

double distance_to_boundary(const PlanarDomain& domain, double x, double y) {
  double d = distance_to_loop(domain.outer, {x, y});
  for (const auto& h : domain.holes) d = std::min(d, distance_to_loop(h, {x, y}));
  return d;
}

bool domain_contains(const PlanarDomain& domain, double x, double y) {
  const P2 p{x, y};
  if (distance_to_boundary(domain, x, y) == 0) return true;
  if (!strictly_inside(domain.outer, p)) return false;
  return std::none_of(domain.holes.begin(), domain.holes.end(),
                      [&](const DomainLoop& h) { return strictly_inside(h, p); });
}

double domain_area(const PlanarDomain& domain) {
  auto area = [](const DomainLoop& l) {
    return l.kind == DomainLoop::Kind::circle ? std::numbers::pi * l.radius * l.radius
                                              : std::abs(signed_area(l.vertices));
  };
  double a = area(domain.outer);
  for (const auto& h : domain.holes) a -= area(h);
  return a;
}

std::array<double, 6> domain_bounding_box(const PlanarDomain& domain) {
  const DomainLoop& o = domain.outer;
  if (o.kind == DomainLoop::Kind::circle)
    return {o.center[0] - o.radius, o.center[1] - o.radius, 0,
            o.center[0] + o.radius, o.center[1] + o.radius, 0};
  std::array<double, 6> box{o.vertices[0][0], o.vertices[0][1], 0,
                            o.vertices[0][0], o.vertices[0][1], 0};
  for (const auto& p : o.vertices) {
    box[0] = std::min(box[0], p[0]);
    box[1] = std::min(box[1], p[1]);
    box[3] = std::max(box[3], p[0]);
    box[4] = std::max(box[4], p[1]);
  }
  return box;
}

}  // namespace quadval
