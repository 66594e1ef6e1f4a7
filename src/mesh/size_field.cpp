#include "quadval/size_field.hpp"

#include <algorithm>
#include <atomic>
#include <cfenv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <unordered_map>

#include <fmt/core.h>
#include <muParser.h>

#include "quadval/error.hpp"
#include "quadval/mesh.hpp"

namespace quadval {

struct SizeField::Impl {
  std::string expression;
  std::uint64_t id = 0;   // unique per parsed expression: the key of the per-thread parsers
  bool is_constant = false;
  double constant_value = 0.0;
};

namespace {

std::atomic<std::uint64_t> g_next_id{1};

// One muparser instance bound to its own x, y, z. The parser keeps pointers to them, so the
// struct lives on the heap and never moves.
struct BoundParser {
  double x = 0.0, y = 0.0, z = 0.0;
  mu::Parser parser;

  explicit BoundParser(const std::string& expression) {
    parser.DefineVar("x", &x);
    parser.DefineVar("y", &y);
    parser.DefineVar("z", &z);
    parser.DefineConst("pi", std::numbers::pi);
    parser.DefineConst("e", std::numbers::e);
    parser.SetExpr(expression);
  }
};

// Per-thread parsers, keyed by Impl::id. The last one used is remembered, since a thread
// almost always evaluates one field many times in a row. Entries of fields that no longer
// exist are dropped when the table grows past a few dozen.
struct ThreadParsers {
  std::uint64_t last_id = 0;
  BoundParser* last = nullptr;
  std::unordered_map<std::uint64_t, std::unique_ptr<BoundParser>> by_id;

  BoundParser& get(const SizeField::Impl& impl) {
    if (impl.id == last_id) return *last;
    auto it = by_id.find(impl.id);
    if (it == by_id.end()) {
      if (by_id.size() >= 64) by_id.clear();
      it = by_id.emplace(impl.id, std::make_unique<BoundParser>(impl.expression)).first;
    }
    last_id = impl.id;
    last = it->second.get();
    return *last;
  }
};

thread_local ThreadParsers t_parsers;

// A user's expression may produce NaN or inf (sqrt(-1), 1/0): that is input, not a bug, so
// it must not trip the floating-point traps that debug test runs enable (STYLE.md §11).
// Costs nothing when no trap is enabled.
class PauseFpTraps {
 public:
  PauseFpTraps() : active_(fegetexcept() != 0) {
    if (active_) feholdexcept(&env_);
  }
  ~PauseFpTraps() {
    if (active_) {
      feclearexcept(FE_ALL_EXCEPT);
      fesetenv(&env_);
    }
  }
  PauseFpTraps(const PauseFpTraps&) = delete;
  PauseFpTraps& operator=(const PauseFpTraps&) = delete;

 private:
  bool active_;
  std::fenv_t env_;
};

std::string source_name(const std::string& expression) {
  return fmt::format("size expression '{}'", expression);
}

}  // namespace

SizeField SizeField::from_expression(std::string expression) {
  const std::string where = source_name(expression);
  if (expression.find_first_not_of(" \t\r\n") == std::string::npos)
    throw InputError::in_file(where, "empty expression; expected h(x, y, z), e.g. 0.1 + 0.05*x");
  try {
    BoundParser probe(expression);
    // GetUsedVar parses with undefined variables tolerated and lists every name used, so an
    // unknown one can be named; Eval then parses for real and reports syntax errors.
    for (const auto& [name, ptr] : probe.parser.GetUsedVar()) {
      if (name != "x" && name != "y" && name != "z")
        throw InputError::in_file(
            where, fmt::format("unknown variable '{}'; only x, y and z are defined", name));
    }
    (void)probe.parser.Eval();
  } catch (const mu::Parser::exception_type& e) {
    throw InputError::at_offset(where, e.GetPos(),
                                fmt::format("does not parse: {}", e.GetMsg()));
  }
  auto impl = std::make_shared<Impl>();
  impl->expression = std::move(expression);
  impl->id = g_next_id.fetch_add(1);
  return SizeField(std::move(impl));
}

SizeField SizeField::constant(double value) {
  QV_ASSERT(std::isfinite(value) && value > 0, "constant size " << value);
  auto impl = std::make_shared<Impl>();
  impl->expression = fmt::format("{}", value);
  impl->id = g_next_id.fetch_add(1);
  impl->is_constant = true;
  impl->constant_value = value;
  return SizeField(std::move(impl));
}

double SizeField::operator()(double x, double y, double z) const {
  if (impl_->is_constant) return impl_->constant_value;
  BoundParser& p = t_parsers.get(*impl_);
  p.x = x;
  p.y = y;
  p.z = z;
  try {
    const PauseFpTraps pause;
    return p.parser.Eval();
  } catch (const mu::Parser::exception_type&) {
    // Parsing was checked in from_expression; evaluation errors (none are known for
    // muparser's built-ins, which return NaN or inf) are reported as "not a number".
    return std::numeric_limits<double>::quiet_NaN();
  }
}

const std::string& SizeField::expression() const noexcept { return impl_->expression; }

void SizeField::check_positive_at(std::span<const double> coords, const std::string& what) const {
  QV_ASSERT(coords.size() % 3 == 0, "coords size " << coords.size());
  for (std::size_t i = 0; i < coords.size() / 3; ++i) {
    const double x = coords[3 * i], y = coords[3 * i + 1], z = coords[3 * i + 2];
    const double h = (*this)(x, y, z);
    if (!(std::isfinite(h) && h > 0))
      throw InputError::in_file(
          source_name(impl_->expression),
          fmt::format("h = {} at {} {} ({}, {}, {}); a size field must be positive", h, what,
                      i, x, y, z));
  }
}

void SizeField::check_positive_on_box(const std::array<double, 6>& box, int n) const {
  QV_ASSERT(n >= 1, "n " << n);
  int steps[3];
  for (int d = 0; d < 3; ++d) steps[d] = box[3 + d] > box[d] ? n : 0;
  for (int i = 0; i <= steps[0]; ++i)
    for (int j = 0; j <= steps[1]; ++j)
      for (int k = 0; k <= steps[2]; ++k) {
        const int ijk[3] = {i, j, k};
        double p[3];
        for (int d = 0; d < 3; ++d)
          p[d] = steps[d] == 0 ? box[d]
                               : box[d] + (box[3 + d] - box[d]) * ijk[d] / steps[d];
        const double h = (*this)(p[0], p[1], p[2]);
        if (!(std::isfinite(h) && h > 0))
          throw InputError::in_file(
              source_name(impl_->expression),
              fmt::format("h = {} at ({}, {}, {}), inside the geometry's bounding box; a size "
                          "field must be positive",
                          h, p[0], p[1], p[2]));
      }
}

namespace {

// Adaptive Simpson on [t0, t1] for f(t) = 1/h(a + t (b - a)); f0, fm, f1 at t0, mid, t1.
template <class F>
double simpson(const F& f, double t0, double t1, double f0, double fm, double f1, double whole,
               double tol, int depth) {
  const double tm = 0.5 * (t0 + t1);
  const double fl = f(0.5 * (t0 + tm)), fr = f(0.5 * (tm + t1));
  const double left = (tm - t0) / 6.0 * (f0 + 4.0 * fl + fm);
  const double right = (t1 - tm) / 6.0 * (fm + 4.0 * fr + f1);
  const double delta = left + right - whole;
  if (!std::isfinite(delta)) return std::numeric_limits<double>::infinity();
  if (depth <= 0 || std::abs(delta) <= 15.0 * tol) return left + right + delta / 15.0;
  return simpson(f, t0, tm, f0, fl, fm, left, 0.5 * tol, depth - 1) +
         simpson(f, tm, t1, fm, fr, f1, right, 0.5 * tol, depth - 1);
}

}  // namespace

double normalized_edge_length(const SizeField& h, const std::array<double, 3>& a,
                              const std::array<double, 3>& b) {
  const std::array<double, 3> d{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (length == 0.0) return 0.0;
  // 1/h along the segment; a non-positive h makes the length infinite.
  auto f = [&](double t) {
    const double v = h(a[0] + t * d[0], a[1] + t * d[1], a[2] + t * d[2]);
    return std::isfinite(v) && v > 0 ? 1.0 / v : std::numeric_limits<double>::infinity();
  };
  const double f0 = f(0.0), fm = f(0.5), f1 = f(1.0);
  if (!std::isfinite(f0 + f1 + fm)) return std::numeric_limits<double>::infinity();
  const double whole = (f0 + 4.0 * fm + f1) / 6.0;
  // Relative tolerance 1e-8 on the integral of 1/h over t in [0, 1]; depth 12 (at most 4096
  // panels) caps the work for a field with a kink or a jump.
  const double integral = simpson(f, 0.0, 1.0, f0, fm, f1, whole, 1e-8 * whole, 12);
  return length * integral;
}

std::vector<double> mesh_normalized_edge_lengths(const Mesh& mesh, const SizeField& h) {
  std::vector<std::pair<NodeIndex, NodeIndex>> edges;
  for (const ElementBlock& block : mesh.blocks) {
    if (block.type->dim != 2) continue;
    const int corners = family_num_vertices(block.type->family);
    if (corners < 3) continue;
    for (std::size_t e = 0; e < block.size(); ++e) {
      const auto n = block.element(e);
      for (int k = 0; k < corners; ++k) {
        const NodeIndex a = n[k], b = n[(k + 1) % corners];
        edges.emplace_back(std::min(a, b), std::max(a, b));
      }
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<double> lengths(edges.size());
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < edges.size(); ++i)
    lengths[i] = normalized_edge_length(h, mesh.node(edges[i].first), mesh.node(edges[i].second));
  return lengths;
}

double efficiency_index(std::span<const double> normalized_lengths) {
  QV_ASSERT(!normalized_lengths.empty(), "no edges");
  double sum = 0;
  for (double l : normalized_lengths) sum += l < 1 ? l - 1 : 1 / l - 1;  // 1/inf - 1 = -1
  return 100.0 * std::exp(sum / static_cast<double>(normalized_lengths.size()));
}

}  // namespace quadval
