#pragma once
// Section readers shared by ASCII and binary MSH files. A "source" yields the values of a
// section in order; AsciiSource parses tokens, BinarySource reads fixed-width values
// (MSH 4.1: int = 4 bytes, size_t = 8 bytes; MSH 2.2 binary uses int throughout). The
// token order is the same in both encodings, except for MSH 2.2 binary elements, which
// are grouped under headers (read_elements22_binary).

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include <fmt/core.h>

#include "io/msh_reader.hpp"
#include "io/parallel_lines.hpp"
#include "quadval/element_type.hpp"

namespace quadval::io {

/// Values from text: every number is a token.
struct AsciiSource {
  TextCursor& in;

  std::int32_t int32(std::string_view what) {
    return static_cast<std::int32_t>(in.integer(what, std::numeric_limits<std::int32_t>::min(),
                                                std::numeric_limits<std::int32_t>::max()));
  }
  std::uint64_t size(std::string_view what) { return in.unsigned_integer(what); }
  double real(std::string_view what) { return in.real(what); }
  /// Fails unless `count` items of `tokens_each` tokens (>= 2 bytes each) can fit.
  void require(std::uint64_t count, std::uint64_t tokens_each, std::uint64_t /*bytes_each*/,
               std::string_view what) {
    const std::uint64_t room = in.remaining() / (2 * tokens_each);
    if (count > room)
      in.fail_at_token(fmt::format("{} {} cannot fit in the {} bytes left in the file", count, what,
                                   in.remaining()));
  }
  void begin_record() { in.begin_record(); }
  void end_record(std::string_view what) { in.end_record(what); }
  void release_parsed() noexcept { in.release_parsed(); }
  [[noreturn]] void fail(const std::string& message) { in.fail_at_token(message); }
  std::size_t where() const { return static_cast<std::size_t>(in.line()); }
  /// A large block's lines on several threads (parallel_lines.hpp); false: read them one
  /// by one.
  bool element_lines(std::uint64_t count, std::uint64_t nodes_each, const TagIndex& index, std::vector<Tag>& tags,
                     std::vector<NodeIndex>& nodes) {
    return read_element_lines(in, count, nodes_each, index, tags, nodes);
  }
  bool tag_lines(std::uint64_t count, std::vector<Tag>& tags) { return read_tag_lines(in, count, tags); }
  bool coordinate_lines(std::uint64_t count, std::vector<double>& coords) {
    return read_coordinate_lines(in, count, coords);
  }
  bool node22_lines(std::uint64_t count, std::vector<Tag>& tags, std::vector<double>& coords) {
    return read_node22_lines(in, count, tags, coords);
  }
  /// Moves back to `mark` (tag_lines' lines read again one by one).
  TextCursor::Mark mark() const noexcept { return in.mark(); }
  void rewind(const TextCursor::Mark& m) noexcept { in.rewind(m); }
};

/// Values from binary data; `size_bytes` is the width of a size_t field.
struct BinarySource {
  ByteCursor& in;

  std::int32_t int32(std::string_view what) { return in.i32(what); }
  std::uint64_t size(std::string_view what) { return in.u64(what); }
  double real(std::string_view what) {
    const double v = in.f64(what);
    if (!std::isfinite(v))
      in.fail_at(in.last_position(), fmt::format("{} is {}, expected a finite number", what, v));
    return v;
  }
  void require(std::uint64_t count, std::uint64_t /*tokens_each*/, std::uint64_t bytes_each,
               std::string_view what) {
    in.require(count, bytes_each, what);
  }
  void begin_record() { in.release_parsed(); }
  void end_record(std::string_view) {}
  void release_parsed() noexcept { in.release_parsed(); }
  [[noreturn]] void fail(const std::string& message) { in.fail_at(in.last_position(), message); }
  std::size_t where() const { return in.position(); }
  bool element_lines(std::uint64_t, std::uint64_t, const TagIndex&, std::vector<Tag>&, std::vector<NodeIndex>&) {
    return false;
  }
  bool tag_lines(std::uint64_t, std::vector<Tag>&) { return false; }
  bool coordinate_lines(std::uint64_t, std::vector<double>&) { return false; }
  bool node22_lines(std::uint64_t, std::vector<Tag>&, std::vector<double>&) { return false; }
  int mark() const noexcept { return 0; }
  void rewind(int) noexcept {}
};

/// The type with this MSH id, which must have a fixed node count.
template <class Src>
const ElementType& element_type_or_fail(Src& src, std::int64_t id) {
  const ElementType* t = find_element_type(static_cast<int>(id));
  if (id < 1 || id > 1000 || t == nullptr)
    src.fail(fmt::format("unknown element type id {}, expected a Gmsh element type (1-140)", id));
  if (t->num_nodes == 0)
    src.fail(fmt::format("element type {} ({}) has a variable node count, which is not supported",
                         id, t->name));
  return *t;
}

template <class Src>
NodeIndex node_index_or_fail(Src& src, const MshReadState& state, std::uint64_t node_tag,
                             std::uint64_t element_tag) {
  const std::uint32_t i = state.node_index.find(node_tag);
  if (i == TagIndex::kMissing)
    src.fail(fmt::format("element {} refers to node tag {}, which is not in $Nodes", element_tag,
                         node_tag));
  return i;
}

template <class Src>
int entity_dimension(Src& src, std::string_view what) {
  const std::int32_t d = src.int32(what);
  if (d < 0 || d > 3) src.fail(fmt::format("{} is {}, expected 0, 1, 2 or 3", what, d));
  return d;
}

/// $Entities of MSH 4.1 (the part after the section name).
template <class Src>
void read_entities41(Src& src, MshReadState& state) {
  std::uint64_t counts[4];
  for (int d = 0; d < 4; ++d) counts[d] = src.size("number of entities");
  std::uint64_t total = 0;
  for (int d = 0; d < 4; ++d) {
    src.require(counts[d], 5, 4 + 24 + 8, "entities");
    total += counts[d];
  }
  src.require(total, 5, 4 + 24 + 8, "entities");
  std::vector<Entity>& entities = state.mesh.entities;
  entities.reserve(static_cast<std::size_t>(total));
  for (int d = 0; d < 4; ++d) {
    for (std::uint64_t i = 0; i < counts[d]; ++i) {
      Entity e;
      e.dim = d;
      e.tag = src.int32("entity tag");
      if (d == 0) {
        for (int k = 0; k < 3; ++k) e.box[k] = e.box[k + 3] = src.real("point coordinate");
      } else {
        for (int k = 0; k < 6; ++k) e.box[k] = src.real("bounding box coordinate");
      }
      const std::uint64_t num_physicals = src.size("number of physical tags");
      src.require(num_physicals, 1, 4, "physical tags");
      e.physical_tags.reserve(static_cast<std::size_t>(num_physicals));
      for (std::uint64_t k = 0; k < num_physicals; ++k) e.physical_tags.push_back(src.int32("physical tag"));
      if (d > 0) {
        const std::uint64_t num_bounding = src.size("number of bounding entities");
        src.require(num_bounding, 1, 4, "bounding entity tags");
        e.boundary_tags.reserve(static_cast<std::size_t>(num_bounding));
        for (std::uint64_t k = 0; k < num_bounding; ++k)
          e.boundary_tags.push_back(src.int32("bounding entity tag"));
      }
      entities.push_back(std::move(e));
    }
  }
  state.have_entities = true;
}

/// $Nodes of MSH 4.1.
template <class Src>
void read_nodes41(Src& src, MshReadState& state) {
  const std::uint64_t num_blocks = src.size("number of node blocks");
  const std::uint64_t num_nodes = src.size("number of nodes");
  src.size("minimum node tag");
  src.size("maximum node tag");
  src.require(num_blocks, 4, 20, "node blocks");
  src.require(num_nodes, 4, 32, "nodes");
  if (num_nodes >= TagIndex::kMissing)
    src.fail(fmt::format("{} nodes is more than quadval supports (2^32 - 1)", num_nodes));
  Mesh& mesh = state.mesh;
  mesh.node_tags.reserve(static_cast<std::size_t>(num_nodes));
  mesh.coords.reserve(3 * static_cast<std::size_t>(num_nodes));
  mesh.node_blocks.reserve(static_cast<std::size_t>(num_blocks));
  state.node_index = TagIndex(num_nodes);
  std::uint64_t total = 0;
  for (std::uint64_t b = 0; b < num_blocks; ++b) {
    NodeBlock block;
    block.entity_dim = entity_dimension(src, "entity dimension of a node block");
    block.entity_tag = src.int32("entity tag of a node block");
    const std::int32_t parametric = src.int32("parametric flag (0 or 1)");
    if (parametric != 0 && parametric != 1)
      src.fail(fmt::format("parametric flag is {}, expected 0 or 1", parametric));
    const std::uint64_t count = src.size("number of nodes in the block");
    if (count > num_nodes - total)
      src.fail(fmt::format("node blocks hold more nodes than the {} of the $Nodes header", num_nodes));
    const int num_param = parametric ? block.entity_dim : 0;
    src.require(count, 4 + static_cast<std::uint64_t>(num_param),
                8 * (4 + static_cast<std::uint64_t>(num_param)), "nodes");
    block.first = static_cast<std::size_t>(total);
    block.count = static_cast<std::size_t>(count);
    // The tags of a large block read at once; a tag 0 or a repeated one is then reported
    // from the lines read one by one again (the index rebuilt from the earlier blocks').
    const auto tags_at = src.mark();
    if (src.tag_lines(count, mesh.node_tags)) {
      for (std::uint64_t i = 0; i < count; ++i) {
        const std::uint64_t tag = mesh.node_tags[static_cast<std::size_t>(total + i)];
        if (tag != 0 && state.node_index.insert(tag, static_cast<std::uint32_t>(total + i))) continue;
        mesh.node_tags.resize(static_cast<std::size_t>(total));
        state.node_index = TagIndex(num_nodes);
        for (std::uint64_t k = 0; k < total; ++k)
          state.node_index.insert(mesh.node_tags[static_cast<std::size_t>(k)], static_cast<std::uint32_t>(k));
        src.rewind(tags_at);
        break;
      }
    }
    for (std::uint64_t i = mesh.node_tags.size() - total; i < count; ++i) {
      const std::uint64_t tag = src.size("node tag");
      if (tag == 0) src.fail("node tag 0, expected a tag >= 1");
      if (!state.node_index.insert(tag, static_cast<std::uint32_t>(total + i)))
        src.fail(fmt::format("node tag {} appears twice", tag));
      mesh.node_tags.push_back(tag);
      src.release_parsed();
    }
    const bool coordinates_read = num_param == 0 && src.coordinate_lines(count, mesh.coords);
    for (std::uint64_t i = 0; i < count && !coordinates_read; ++i) {
      mesh.coords.push_back(src.real("node x coordinate"));
      mesh.coords.push_back(src.real("node y coordinate"));
      mesh.coords.push_back(src.real("node z coordinate"));
      for (int k = 0; k < num_param; ++k) src.real("parametric node coordinate");
      src.release_parsed();
    }
    if (num_param > 0 && !state.warned_parametric) {
      state.warned_parametric = true;
      state.warn("parametric node coordinates are not used and were dropped");
    }
    total += count;
    mesh.node_blocks.push_back(block);
  }
  if (total != num_nodes)
    src.fail(fmt::format("the $Nodes header says {} nodes, its blocks hold {}", num_nodes, total));
  state.have_nodes = true;
}

/// $Elements of MSH 4.1.
template <class Src>
void read_elements41(Src& src, MshReadState& state) {
  if (!state.have_nodes) src.fail("$Elements comes before $Nodes");
  const std::uint64_t num_blocks = src.size("number of element blocks");
  const std::uint64_t num_elements = src.size("number of elements");
  src.size("minimum element tag");
  src.size("maximum element tag");
  src.require(num_blocks, 4, 20, "element blocks");
  src.require(num_elements, 2, 16, "elements");
  Mesh& mesh = state.mesh;
  mesh.blocks.reserve(static_cast<std::size_t>(num_blocks));
  std::uint64_t total = 0;
  for (std::uint64_t b = 0; b < num_blocks; ++b) {
    ElementBlock block;
    block.entity_dim = entity_dimension(src, "entity dimension of an element block");
    block.entity_tag = src.int32("entity tag of an element block");
    block.type = &element_type_or_fail(src, src.int32("element type"));
    const std::uint64_t count = src.size("number of elements in the block");
    if (count > num_elements - total)
      src.fail(fmt::format("element blocks hold more elements than the {} of the $Elements header",
                           num_elements));
    const auto nn = static_cast<std::uint64_t>(block.type->num_nodes);
    src.require(count, 1 + nn, 8 * (1 + nn), "elements");
    block.tags.reserve(static_cast<std::size_t>(count));
    block.nodes.reserve(static_cast<std::size_t>(count * nn));
    const std::string what = fmt::format("an element tag and {} node tags ({})", nn, block.type->name);
    const bool lines_read = src.element_lines(count, nn, state.node_index, block.tags, block.nodes);
    for (std::uint64_t e = 0; e < count && !lines_read; ++e) {
      src.begin_record();
      const std::uint64_t tag = src.size("element tag");
      block.tags.push_back(tag);
      for (std::uint64_t k = 0; k < nn; ++k)
        block.nodes.push_back(node_index_or_fail(src, state, src.size("node tag"), tag));
      src.end_record(what);
    }
    total += count;
    mesh.blocks.push_back(std::move(block));
  }
  if (total != num_elements)
    src.fail(fmt::format("the $Elements header says {} elements, its blocks hold {}", num_elements,
                         total));
  state.have_elements = true;
}

/// The node lines of MSH 2.2 after the count (tag x y z each).
template <class Src>
void read_nodes22(Src& src, MshReadState& state, std::uint64_t num_nodes) {
  src.require(num_nodes, 4, 28, "nodes");
  if (num_nodes >= TagIndex::kMissing)
    src.fail(fmt::format("{} nodes is more than quadval supports (2^32 - 1)", num_nodes));
  Mesh& mesh = state.mesh;
  mesh.node_tags.reserve(static_cast<std::size_t>(num_nodes));
  mesh.coords.reserve(3 * static_cast<std::size_t>(num_nodes));
  state.node_index = TagIndex(num_nodes);
  // A large section read at once; a repeated tag is then reported from the lines read one by
  // one again.
  const std::size_t tags_before = mesh.node_tags.size(), coords_before = mesh.coords.size();
  const auto at = src.mark();
  if (src.node22_lines(num_nodes, mesh.node_tags, mesh.coords)) {
    bool unique = true;
    for (std::uint64_t i = 0; i < num_nodes && unique; ++i)
      unique = state.node_index.insert(mesh.node_tags[tags_before + i], static_cast<std::uint32_t>(i));
    if (unique) {
      state.have_nodes = true;
      return;
    }
    mesh.node_tags.resize(tags_before);
    mesh.coords.resize(coords_before);
    state.node_index = TagIndex(num_nodes);
    src.rewind(at);
  }
  for (std::uint64_t i = 0; i < num_nodes; ++i) {
    src.begin_record();
    const std::int32_t tag = src.int32("node tag");
    if (tag < 1) src.fail(fmt::format("node tag {}, expected a tag >= 1", tag));
    if (!state.node_index.insert(static_cast<std::uint64_t>(tag), static_cast<std::uint32_t>(i)))
      src.fail(fmt::format("node tag {} appears twice", tag));
    mesh.node_tags.push_back(static_cast<Tag>(tag));
    mesh.coords.push_back(src.real("node x coordinate"));
    mesh.coords.push_back(src.real("node y coordinate"));
    mesh.coords.push_back(src.real("node z coordinate"));
    src.end_record("a node tag and 3 coordinates");
  }
  state.have_nodes = true;
}

/// One MSH 2.2 element after its type and tags: its node tags.
template <class Src>
void read_element22_nodes(Src& src, MshReadState& state, const ElementType& type,
                          std::uint64_t tag, std::int32_t physical, std::int32_t elementary,
                          std::size_t where) {
  state.elements22.push_back({tag, &type, physical, elementary});
  state.nodes22_offset.push_back(state.nodes22.size());
  state.positions22.push_back(where);
  for (int k = 0; k < type.num_nodes; ++k) {
    const std::int32_t n = src.int32("node tag");
    state.nodes22.push_back(node_index_or_fail(src, state, static_cast<std::uint64_t>(n < 0 ? 0 : n), tag));
  }
}

/// Tags of a MSH 2.2 element: physical, elementary, then partitions (dropped).
template <class Src>
void read_element22_tags(Src& src, MshReadState& state, std::int32_t num_tags,
                         std::int32_t& physical, std::int32_t& elementary) {
  if (num_tags < 0 || num_tags > 1000)
    src.fail(fmt::format("number of element tags is {}, expected 0 to 1000", num_tags));
  physical = 0;
  elementary = 0;
  for (std::int32_t k = 0; k < num_tags; ++k) {
    const std::int32_t v = src.int32("element tag (physical, elementary, partitions)");
    if (k == 0) physical = v;
    if (k == 1) elementary = v;
  }
  if (num_tags > 2 && !state.warned_partitions) {
    state.warned_partitions = true;
    state.warn("MSH 2.2 partition tags are not used and were dropped");
  }
}

}  // namespace quadval::io
