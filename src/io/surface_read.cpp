// STL, OBJ and OFF surface readers. Faces of 3 vertices become Triangle 3, of 4
// Quadrilateral 4; both blocks lie on entity (2, 1).
#include "io/surface_read.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <span>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>

#include <fmt/core.h>
#include <omp.h>

#include "io/byte_cursor.hpp"
#include "io/text_cursor.hpp"
#include "quadval/error.hpp"

namespace quadval::io {

namespace {

/// Collects nodes and faces, then makes the Mesh.
class SurfaceBuilder {
 public:
  void add_node(double x, double y, double z) {
    coords_.insert(coords_.end(), {x, y, z});
  }
  /// Adds nodes from x, y, z triples.
  void add_nodes(std::span<const double> xyz) { coords_.insert(coords_.end(), xyz.begin(), xyz.end()); }
  std::size_t num_nodes() const noexcept { return coords_.size() / 3; }
  const double* node(NodeIndex n) const noexcept { return coords_.data() + 3 * std::size_t{n}; }
  /// Adds a face of 3 or 4 node indices (checked by the caller).
  void add_face(std::span<const NodeIndex> nodes) {
    std::vector<NodeIndex>& into = nodes.size() == 3 ? tri_nodes_ : quad_nodes_;
    std::vector<Tag>& tags = nodes.size() == 3 ? tri_tags_ : quad_tags_;
    into.insert(into.end(), nodes.begin(), nodes.end());
    tags.push_back(++num_faces_);
  }
  void reserve(std::size_t nodes, std::size_t faces) {
    coords_.reserve(3 * nodes);
    tri_nodes_.reserve(3 * faces);
    tri_tags_.reserve(faces);
  }
  Mesh finish() {
    Mesh mesh;
    mesh.node_tags.resize(num_nodes());
    for (std::size_t i = 0; i < mesh.node_tags.size(); ++i) mesh.node_tags[i] = i + 1;
    mesh.coords = std::move(coords_);
    auto add_block = [&](int gmsh_id, std::vector<Tag>& tags, std::vector<NodeIndex>& nodes) {
      if (tags.empty()) return;
      ElementBlock b;
      b.type = find_element_type(gmsh_id);
      b.entity_dim = 2;
      b.entity_tag = 1;
      b.tags = std::move(tags);
      b.nodes = std::move(nodes);
      mesh.blocks.push_back(std::move(b));
    };
    add_block(2, tri_tags_, tri_nodes_);
    add_block(3, quad_tags_, quad_nodes_);
    return mesh;
  }

 private:
  std::vector<double> coords_;
  std::vector<NodeIndex> tri_nodes_, quad_nodes_;
  std::vector<Tag> tri_tags_, quad_tags_;
  Tag num_faces_ = 0;
};

/// Merges STL vertices with identical coordinates, numbered in order of first appearance:
/// open addressing over the builder's own coordinates (a slot holds a node index), since a
/// node-based map cost three quarters of reading 1M binary STL triangles (0.5-0.7 s).
class VertexMerger {
 public:
  VertexMerger(SurfaceBuilder& builder, std::size_t expected_nodes) : builder_(builder) {
    std::size_t capacity = 1024;
    while (capacity < 2 * expected_nodes) capacity *= 2;
    slots_.assign(capacity, kEmpty);
  }
  NodeIndex index_of(double x, double y, double z) {
    // Coordinates are finite (the readers check), where == is equality of the values and
    // -0.0 == +0.0; the hash takes x + 0.0, which turns -0.0 into +0.0, to agree with it.
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t at = hash(x, y, z) & mask;; at = (at + 1) & mask) {
      const NodeIndex n = slots_[at];
      if (n == kEmpty) {
        const auto added = static_cast<NodeIndex>(builder_.num_nodes());
        builder_.add_node(x, y, z);
        slots_[at] = added;
        if (2 * builder_.num_nodes() > slots_.size()) grow();
        return added;
      }
      const double* p = builder_.node(n);
      if (p[0] == x && p[1] == y && p[2] == z) return n;
    }
  }

 private:
  static constexpr NodeIndex kEmpty = 0xffffffffu;
  // SplitMix64's finaliser: every bit of the input reaches the low bits that index the
  // slots (coordinates read from float have their low 29 mantissa bits zero).
  static std::uint64_t mix(std::uint64_t z) noexcept {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  static std::size_t hash(double x, double y, double z) noexcept {
    const std::uint64_t h = mix(std::bit_cast<std::uint64_t>(x + 0.0) +
                                mix(std::bit_cast<std::uint64_t>(y + 0.0) + mix(std::bit_cast<std::uint64_t>(z + 0.0))));
    return static_cast<std::size_t>(h);
  }
  // Twice the slots, every node placed again (at most half full before).
  void grow() {
    std::vector<NodeIndex> old(2 * slots_.size(), kEmpty);
    old.swap(slots_);
    const std::size_t mask = slots_.size() - 1;
    for (NodeIndex n : old) {
      if (n == kEmpty) continue;
      const double* p = builder_.node(n);
      std::size_t at = hash(p[0], p[1], p[2]) & mask;
      while (slots_[at] != kEmpty) at = (at + 1) & mask;
      slots_[at] = n;
    }
  }
  SurfaceBuilder& builder_;
  std::vector<NodeIndex> slots_;
};

Mesh read_stl_binary(std::string_view bytes, const std::string& file, std::uint32_t count) {
  ByteCursor in(bytes, file, 84);
  SurfaceBuilder builder;
  builder.reserve(count / 2 + 3, count);
  VertexMerger merger(builder, count / 2 + 3);
  for (std::uint32_t t = 0; t < count; ++t) {
    for (int k = 0; k < 3; ++k) in.f32("facet normal");
    std::array<NodeIndex, 3> face;
    for (int v = 0; v < 3; ++v) {
      double x[3];
      for (double& c : x) {
        c = in.f32("vertex coordinate");
        if (!std::isfinite(c))
          in.fail_at(in.last_position(), fmt::format("vertex coordinate of facet {} is {}, expected a finite number", t + 1, c));
      }
      face[v] = merger.index_of(x[0], x[1], x[2]);
    }
    in.u16("attribute byte count");
    builder.add_face(face);
  }
  return builder.finish();
}

Mesh read_stl_ascii(std::string_view bytes, const std::string& file) {
  TextCursor in(bytes, file);
  SurfaceBuilder builder;
  VertexMerger merger(builder, bytes.size() / 512);  // an ASCII facet takes about 250 bytes
  in.expect("solid");
  in.rest_of_line();  // the solid's name
  for (;;) {
    const std::string_view word = in.token("facet or endsolid");
    if (word == "endsolid") {
      in.rest_of_line();
      if (in.at_end()) break;
      in.expect("solid");  // another solid follows
      in.rest_of_line();
      continue;
    }
    if (word != "facet") in.fail_at_token(fmt::format("expected facet or endsolid, found '{}'", TextCursor::shorten(word)));
    in.expect("normal");
    for (int k = 0; k < 3; ++k) in.real("normal component");
    in.expect("outer");
    in.expect("loop");
    std::array<NodeIndex, 3> face;
    for (int v = 0; v < 3; ++v) {
      in.expect("vertex");
      const double x = in.real("vertex x coordinate");
      const double y = in.real("vertex y coordinate");
      const double z = in.real("vertex z coordinate");
      face[v] = merger.index_of(x, y, z);
    }
    in.expect("endloop");
    in.expect("endfacet");
    builder.add_face(face);
  }
  return builder.finish();
}

/// Splits text into lines and lines into blank-separated fields; `comment` starts a
/// comment that runs to the line end (0 for none).
class LineFields {
 public:
  LineFields(std::string_view bytes, std::string file, char comment)
      : bytes_(bytes), file_(std::move(file)), comment_(comment) {}

  /// Moves to the next line with at least one field; false at the end of the file.
  bool next() {
    while (pos_ < bytes_.size()) {
      std::size_t end = bytes_.find('\n', pos_);
      if (end == std::string_view::npos) end = bytes_.size();
      std::string_view line = bytes_.substr(pos_, end - pos_);
      pos_ = end + 1;
      ++line_;
      if (comment_ != 0) {
        const std::size_t c = line.find(comment_);
        if (c != std::string_view::npos) line = line.substr(0, c);
      }
      fields_.clear();
      std::size_t i = 0;
      while (i < line.size()) {
        while (i < line.size() && TextCursor::is_space(line[i])) ++i;
        const std::size_t start = i;
        while (i < line.size() && !TextCursor::is_space(line[i])) ++i;
        if (i > start) fields_.push_back(line.substr(start, i - start));
      }
      if (!fields_.empty()) return true;
    }
    return false;
  }
  std::size_t size() const noexcept { return fields_.size(); }
  std::string_view operator[](std::size_t i) const noexcept { return fields_[i]; }
  long line() const noexcept { return line_; }
  std::size_t remaining() const noexcept { return pos_ < bytes_.size() ? bytes_.size() - pos_ : 0; }

  [[noreturn]] void fail(const std::string& message) const { throw InputError::at_line(file_, line_, message); }

  double real(std::size_t i, std::string_view what) const {
    if (i >= fields_.size()) fail(fmt::format("expected {}, found the end of the line", what));
    std::string_view t = fields_[i];
    const char* first = t.data();
    const char* last = t.data() + t.size();
    if (first < last && *first == '+') ++first;
    double v = 0;
    auto [ptr, ec] = std::from_chars(first, last, v);
    if (ec != std::errc() || ptr != last) fail(fmt::format("expected {} (a number), found '{}'", what, TextCursor::shorten(t)));
    if (!std::isfinite(v)) fail(fmt::format("{} is '{}', expected a finite number", what, TextCursor::shorten(t)));
    return v;
  }
  /// An integer field, or the integer before the first '/' (OBJ's i/t/n).
  std::int64_t integer(std::size_t i, std::string_view what, bool slash_ok = false) const {
    if (i >= fields_.size()) fail(fmt::format("expected {}, found the end of the line", what));
    std::string_view t = fields_[i];
    if (slash_ok) t = t.substr(0, t.find('/'));
    std::int64_t v = 0;
    auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (ec != std::errc() || ptr != t.data() + t.size())
      fail(fmt::format("expected {} (an integer), found '{}'", what, TextCursor::shorten(fields_[i])));
    return v;
  }

 private:
  std::string_view bytes_;
  std::string file_;
  char comment_;
  std::size_t pos_ = 0;
  long line_ = 0;
  std::vector<std::string_view> fields_;
};

void check_face_size(const LineFields& in, std::size_t n) {
  if (n != 3 && n != 4)
    in.fail(fmt::format("face with {} vertices, expected 3 (triangle) or 4 (quadrangle)", n));
}

}  // namespace

Mesh read_stl(std::string_view bytes, const std::string& file, std::vector<std::string>& /*warnings*/) {
  if (bytes.empty()) throw InputError::in_file(file, "empty file, expected an STL surface");
  if (bytes.size() >= 84) {
    std::uint32_t count;
    std::memcpy(&count, bytes.data() + 80, 4);
    if (84 + 50 * static_cast<std::uint64_t>(count) == bytes.size()) return read_stl_binary(bytes, file, count);
  }
  // ASCII STL never holds a NUL byte; a binary one (even with a "solid" header) nearly always does.
  const bool text = bytes.find('\0') == std::string_view::npos;
  std::size_t start = 0;
  while (start < bytes.size() && TextCursor::is_space(bytes[start])) ++start;
  if (text && bytes.substr(start, 5) == "solid") return read_stl_ascii(bytes, file);
  if (bytes.size() >= 84) {
    std::uint32_t count;
    std::memcpy(&count, bytes.data() + 80, 4);
    throw InputError::at_offset(file, 80, fmt::format("binary STL header says {} triangles, which need {} bytes; the file has {}",
                                                      count, 84 + 50 * static_cast<std::uint64_t>(count), bytes.size()));
  }
  throw InputError::in_file(file, fmt::format("neither ASCII STL (starting with 'solid') nor binary STL (84 + 50 n bytes; "
                                              "the file has {} bytes)", bytes.size()));
}

namespace {

// The statements of a run of whole lines of an OBJ file (all of it, or one thread's part),
// line numbers counted from the run's first line.
struct ObjRun {
  struct Face {
    std::array<std::int64_t, 4> v;  // 1-based; negative: relative, to the run's vertices so far
    int n;
    long line;
    std::uint32_t before;  // the run's vertices before this face
  };
  std::vector<double> coords;
  std::vector<Face> faces;
  std::vector<std::pair<std::string, long>> unknown;  // first use of each unknown statement
};

// Reads the statements of `in` into `run` (InputError at a bad line). Negative indices are
// resolved at once when `absolute` (the run starts the file), else kept for the caller.
void read_obj_statements(LineFields& in, bool absolute, ObjRun& run) {
  while (in.next()) {
    const std::string_view key = in[0];
    if (key == "v") {
      if (in.size() < 4) in.fail("expected 'v x y z'");
      run.coords.insert(run.coords.end(), {in.real(1, "vertex x coordinate"), in.real(2, "vertex y coordinate"),
                                           in.real(3, "vertex z coordinate")});
    } else if (key == "f") {
      check_face_size(in, in.size() - 1);
      const auto before = static_cast<std::uint32_t>(run.coords.size() / 3);
      ObjRun::Face f{{0, 0, 0, 0}, static_cast<int>(in.size() - 1), in.line(), before};
      for (int k = 0; k < f.n; ++k) {
        std::int64_t i = in.integer(1 + static_cast<std::size_t>(k), "vertex index", true);
        if (i == 0) in.fail("vertex index 0, expected 1-based or negative indices");
        if (i < 0 && absolute) {  // relative to the vertices read so far
          i += static_cast<std::int64_t>(before) + 1;
          if (i < 1) in.fail(fmt::format("relative vertex index {} points before the first vertex", in[1 + static_cast<std::size_t>(k)]));
        }
        f.v[static_cast<std::size_t>(k)] = i;
      }
      run.faces.push_back(f);
    } else if (key == "vt" || key == "vn" || key == "vp" || key == "g" || key == "o" || key == "s" ||
               key == "usemtl" || key == "mtllib") {
      // Texture, normals, groups and materials say nothing about the geometry we keep.
    } else if (std::none_of(run.unknown.begin(), run.unknown.end(), [&](const auto& u) { return u.first == key; })) {
      run.unknown.emplace_back(key, in.line());
    }
  }
}

// Files from this size on are read in runs of lines on several threads (1M triangles,
// 55 MB: see read_obj).
constexpr std::size_t kParallelObjBytes = std::size_t{1} << 20;

// The file cut into `runs` runs of whole lines, each read on a thread of its own; nullopt
// where a run has an error, or a relative index points before the file's first vertex: the
// whole file is then read as one run, which reports the first error in the file.
std::optional<std::vector<ObjRun>> read_obj_runs(std::string_view bytes, const std::string& file, std::size_t runs) {
  std::vector<std::size_t> cut(runs + 1, bytes.size());
  cut[0] = 0;
  for (std::size_t k = 1; k < runs; ++k) {
    const std::size_t line_end = bytes.find('\n', std::max(cut[k - 1], bytes.size() / runs * k));
    cut[k] = line_end == std::string_view::npos ? bytes.size() : line_end + 1;
  }
  std::vector<ObjRun> out(runs);
  std::vector<char> failed(runs, 0);
#pragma omp parallel for num_threads(static_cast<int>(runs)) schedule(static, 1)
  for (std::size_t k = 0; k < runs; ++k) {
    try {
      LineFields in(bytes.substr(cut[k], cut[k + 1] - cut[k]), file, '#');
      read_obj_statements(in, k == 0, out[k]);
    } catch (...) {
      failed[k] = 1;
    }
  }
  if (std::find(failed.begin(), failed.end(), 1) != failed.end()) return std::nullopt;
  // Runs after the first: their lines and vertices start after the earlier ones'.
  long line0 = 0;
  std::int64_t vertex0 = 0;
  for (std::size_t k = 0; k < runs; ++k) {
    ObjRun& run = out[k];
    for (ObjRun::Face& f : run.faces) {
      f.line += line0;
      for (int j = 0; j < f.n; ++j) {
        std::int64_t& i = f.v[static_cast<std::size_t>(j)];
        if (i < 0 && (i += vertex0 + f.before + 1) < 1) return std::nullopt;
      }
    }
    for (auto& u : run.unknown) u.second += line0;
    line0 += static_cast<long>(std::count(bytes.begin() + static_cast<std::ptrdiff_t>(cut[k]),
                                          bytes.begin() + static_cast<std::ptrdiff_t>(cut[k + 1]), '\n'));
    vertex0 += static_cast<std::int64_t>(run.coords.size() / 3);
  }
  return out;
}

}  // namespace

Mesh read_obj(std::string_view bytes, const std::string& file, std::vector<std::string>& warnings, std::size_t runs,
              std::size_t* runs_used) {
  std::vector<ObjRun> parts;
  if (runs > 1) {
    if (auto r = read_obj_runs(bytes, file, runs)) parts = std::move(*r);
  }
  if (runs_used) *runs_used = std::max<std::size_t>(1, parts.size());
  if (parts.empty()) {
    parts.resize(1);
    LineFields in(bytes, file, '#');
    read_obj_statements(in, true, parts[0]);
  }
  SurfaceBuilder builder;
  std::size_t n = 0, faces = 0;
  for (const ObjRun& run : parts) {
    n += run.coords.size() / 3;
    faces += run.faces.size();
  }
  builder.reserve(n, faces);
  std::vector<std::string_view> warned;
  for (const ObjRun& run : parts) {
    builder.add_nodes(run.coords);
    for (const auto& [key, line] : run.unknown) {
      if (std::find(warned.begin(), warned.end(), key) != warned.end()) continue;
      warned.emplace_back(key);
      warnings.push_back(fmt::format("{}:{}: OBJ statement '{}' is not used and was skipped", file, line,
                                     TextCursor::shorten(key)));
    }
  }
  for (const ObjRun& run : parts)
    for (const ObjRun::Face& f : run.faces) {
      std::array<NodeIndex, 4> nodes{};
      for (int k = 0; k < f.n; ++k) {
        if (f.v[static_cast<std::size_t>(k)] > static_cast<std::int64_t>(n))
          throw InputError::at_line(file, f.line, fmt::format("face refers to vertex {}, the file has {}", f.v[static_cast<std::size_t>(k)], n));
        nodes[static_cast<std::size_t>(k)] = static_cast<NodeIndex>(f.v[static_cast<std::size_t>(k)] - 1);
      }
      builder.add_face(std::span<const NodeIndex>(nodes.data(), static_cast<std::size_t>(f.n)));
    }
  if (n == 0 && faces == 0) throw InputError::in_file(file, "no vertices and no faces, expected an OBJ surface");
  return builder.finish();
}

Mesh read_obj(std::string_view bytes, const std::string& file, std::vector<std::string>& warnings) {
  const auto threads = static_cast<std::size_t>(std::max(1, omp_get_max_threads()));
  const std::size_t runs = bytes.size() < kParallelObjBytes ? 1 : std::min(threads, bytes.size() / (kParallelObjBytes / 2));
  return read_obj(bytes, file, warnings, runs);
}

Mesh read_off(std::string_view bytes, const std::string& file, std::vector<std::string>& /*warnings*/) {
  LineFields in(bytes, file, '#');
  if (!in.next()) throw InputError::in_file(file, "empty file, expected an OFF surface starting with 'OFF'");
  std::size_t first_count = 1;
  if (in[0] != "OFF") {
    if (in[0].size() > 3 && in[0].substr(0, 3) == "OFF") in.fail("expected 'OFF' followed by a blank");
    in.fail(fmt::format("expected 'OFF', found '{}'", TextCursor::shorten(in[0])));
  }
  if (in.size() == 1) {  // the counts are on the next line
    if (!in.next()) in.fail("unexpected end of file, expected the counts 'vertices faces edges'");
    first_count = 0;
  }
  const std::int64_t nv = in.integer(first_count, "number of vertices");
  const std::int64_t nf = in.integer(first_count + 1, "number of faces");
  const auto room = static_cast<std::int64_t>(in.remaining() / 6 + 1);
  if (nv < 0 || nv > room) in.fail(fmt::format("number of vertices {} does not fit the {} bytes left", nv, in.remaining()));
  if (nf < 0 || nf > room) in.fail(fmt::format("number of faces {} does not fit the {} bytes left", nf, in.remaining()));
  SurfaceBuilder builder;
  builder.reserve(static_cast<std::size_t>(nv), static_cast<std::size_t>(nf));
  for (std::int64_t i = 0; i < nv; ++i) {
    if (!in.next()) in.fail(fmt::format("unexpected end of file after {} of {} vertices", i, nv));
    builder.add_node(in.real(0, "vertex x coordinate"), in.real(1, "vertex y coordinate"), in.real(2, "vertex z coordinate"));
  }
  for (std::int64_t i = 0; i < nf; ++i) {
    if (!in.next()) in.fail(fmt::format("unexpected end of file after {} of {} faces", i, nf));
    const std::int64_t k = in.integer(0, "number of face vertices");
    check_face_size(in, static_cast<std::size_t>(k < 0 ? 0 : k));
    if (in.size() < static_cast<std::size_t>(k) + 1) in.fail(fmt::format("face of {} vertices lists {}", k, in.size() - 1));
    std::array<NodeIndex, 4> nodes{};
    for (std::int64_t j = 0; j < k; ++j) {
      const std::int64_t v = in.integer(static_cast<std::size_t>(j) + 1, "vertex index");
      if (v < 0 || v >= nv) in.fail(fmt::format("vertex index {}, expected 0 to {}", v, nv - 1));
      nodes[static_cast<std::size_t>(j)] = static_cast<NodeIndex>(v);
    }
    builder.add_face(std::span<const NodeIndex>(nodes.data(), static_cast<std::size_t>(k)));
  }
  return builder.finish();
}

}  // namespace quadval::io
