// MSH files: $MeshFormat, the section loop, $PhysicalNames, skipped sections, and the
// grouping of MSH 2.2 elements into blocks and entities (conventions in io.hpp).
#include <algorithm>
#include <limits>
#include <unordered_map>

#include <fmt/core.h>

#include "io/msh_reader.hpp"

namespace quadval::io {

namespace {

enum class Version { v22, v41 };

void read_physical_names(TextCursor& in, MshReadState& state) {
  const std::uint64_t count = in.unsigned_integer("number of physical names");
  if (count > in.remaining() / 8)
    in.fail_at_token(fmt::format("{} physical names cannot fit in the {} bytes left", count, in.remaining()));
  for (std::uint64_t i = 0; i < count; ++i) {
    PhysicalGroup g;
    g.dim = static_cast<int>(in.integer("physical group dimension", 0, 3));
    g.tag = static_cast<int>(in.integer("physical group tag", 1, std::numeric_limits<std::int32_t>::max()));
    std::string_view rest = in.rest_of_line();
    const std::size_t open = rest.find('"');
    const std::size_t close = rest.rfind('"');
    if (open == std::string_view::npos || close == open)
      in.fail_at_token(fmt::format("expected a quoted physical group name after tag {}, found '{}'",
                                   g.tag, TextCursor::shorten(rest)));
    g.name = std::string(rest.substr(open + 1, close - open - 1));
    state.mesh.physical_names.push_back(std::move(g));
  }
}

/// Skips to the line after $End<name>.
void skip_section(TextCursor& in, std::string_view name, bool binary) {
  const std::string end_marker = "$End" + std::string(name);
  std::size_t at = in.position();
  for (;;) {
    at = in.data().find(end_marker, at);
    if (at == std::string_view::npos)
      in.fail_at_token(fmt::format("section ${} is not closed by {}", name, end_marker));
    if (at > 0 && (in.data()[at - 1] == '\n' || in.data()[at - 1] == '\r')) break;
    ++at;
  }
  if (binary) in.jump_to(at); else in.advance_to(at);
  in.expect(end_marker);
}

/// The endianness marker of a binary file: an int 1 right after the $MeshFormat line.
void check_endianness(TextCursor& in) {
  in.finish_line("the binary endianness marker");
  ByteCursor bytes(in.data(), in.file(), in.position(), in.source());
  const std::int32_t one = bytes.i32("the endianness marker (int 1)");
  if (one != 1) {
    const auto swapped = static_cast<std::int32_t>(
        ((static_cast<std::uint32_t>(one) & 0xffu) << 24) | ((static_cast<std::uint32_t>(one) & 0xff00u) << 8) |
        ((static_cast<std::uint32_t>(one) >> 8) & 0xff00u) | (static_cast<std::uint32_t>(one) >> 24));
    if (swapped == 1)
      bytes.fail_at(bytes.last_position(),
                    "binary data of the other byte order (the endianness marker reads 16777216, "
                    "expected 1); re-export the file as ASCII or on a machine of this byte order");
    bytes.fail_at(bytes.last_position(), fmt::format("endianness marker is {}, expected the int 1", one));
  }
  in.jump_to(bytes.position());
}

}  // namespace

Mesh read_msh(std::string_view bytes, const std::string& file, std::vector<std::string>& warnings,
              FileBytes* source) {
  TextCursor in(bytes, file, source);
  if (in.at_end()) throw InputError::in_file(file, "empty file, expected a Gmsh MSH file starting with $MeshFormat");
  MshReadState state;
  state.file = file;
  state.warnings = &warnings;

  std::string_view first = in.token("$MeshFormat");
  while (first == "$Comments") {
    skip_section(in, "Comments", false);
    first = in.token("$MeshFormat");
  }
  if (first == "$NOD" || first == "$NOE")
    in.fail_at_token("MSH version 1 file, expected MSH 2.2 or 4.1");
  if (first != "$MeshFormat")
    in.fail_at_token(fmt::format("expected $MeshFormat, found '{}'", TextCursor::shorten(first)));
  const std::string_view version_text = in.token("MSH version (2.2 or 4.1)");
  Version version;
  if (version_text == "4.1") version = Version::v41;
  else if (version_text == "2.2" || version_text == "2.1" || version_text == "2" || version_text == "2.0")
    version = Version::v22;
  else
    in.fail_at_token(fmt::format("MSH version {} is not supported, expected 2.2 or 4.1",
                                 TextCursor::shorten(version_text)));
  const bool binary = in.integer("file type (0 ASCII, 1 binary)", 0, 1) == 1;
  const std::int64_t data_size = in.integer("data size");
  if (data_size != 8) in.fail_at_token(fmt::format("data size {}, expected 8", data_size));
  if (binary) {
    in.report_offsets();
    check_endianness(in);
  }
  in.expect("$EndMeshFormat");

  while (!in.at_end()) {
    const std::string_view token = in.token("a section name");
    if (token.size() < 2 || token[0] != '$')
      in.fail_at_token(fmt::format("expected a section name such as $Nodes, found '{}'",
                                   TextCursor::shorten(token)));
    const std::string name(token.substr(1));
    if (name == "PhysicalNames") {
      read_physical_names(in, state);
    } else if (name == "Entities" && version == Version::v41) {
      if (state.have_entities) in.fail_at_token("second $Entities section");
      if (binary) {
        in.finish_line("binary entity data");
        read_entities41_binary(in, state);
      } else {
        read_entities41_ascii(in, state);
      }
    } else if (name == "Nodes") {
      if (state.have_nodes) in.fail_at_token("second $Nodes section");
      if (version == Version::v41 && binary) {
        in.finish_line("binary node data");
        read_nodes41_binary(in, state);
      } else if (version == Version::v41) {
        read_nodes41_ascii(in, state);
      } else if (binary) {
        read_nodes22_binary(in, state);
      } else {
        read_nodes22_ascii(in, state);
      }
    } else if (name == "Elements") {
      if (state.have_elements) in.fail_at_token("second $Elements section");
      if (version == Version::v41 && binary) {
        if (!state.have_nodes) in.fail_at_token("$Elements comes before $Nodes");
        in.finish_line("binary element data");
        read_elements41_binary(in, state);
      } else if (version == Version::v41) {
        read_elements41_ascii(in, state);
      } else if (binary) {
        read_elements22_binary(in, state);
      } else {
        read_elements22_ascii(in, state);
      }
    } else if (name == "Comments") {
      skip_section(in, name, binary);
      continue;
    } else if (name.rfind("End", 0) == 0) {
      in.fail_at_token(fmt::format("unexpected {} outside its section", token));
    } else {
      state.warn(fmt::format("section ${} is not used by quadval and was skipped", name));
      skip_section(in, name, binary);
      continue;
    }
    in.expect("$End" + name);
  }
  if (!state.have_nodes) in.fail_here("the file ends without a $Nodes section (truncated?)");
  if (!state.have_elements) in.fail_here("the file ends without an $Elements section (truncated?)");
  if (version == Version::v22) finish_msh22(state, binary);
  return std::move(state.mesh);
}

void finish_msh22(MshReadState& state, bool binary) {
  Mesh& mesh = state.mesh;
  const std::size_t n = state.elements22.size();
  auto fail = [&](std::size_t i, const std::string& message) {
    if (binary) throw InputError::at_offset(state.file, static_cast<long long>(state.positions22[i]), message);
    throw InputError::at_line(state.file, static_cast<long>(state.positions22[i]), message);
  };
  auto nodes_of = [&](std::size_t i) {
    return std::span<const NodeIndex>(state.nodes22.data() + state.nodes22_offset[i],
                                      static_cast<std::size_t>(state.elements22[i].type->num_nodes));
  };
  auto pack = [](int a, int b) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
  };
  std::unordered_map<std::uint64_t, std::size_t> block_of;   // (type id, elementary)
  std::unordered_map<std::uint64_t, std::size_t> entity_of;  // (dim, elementary)
  std::vector<std::vector<int>> physicals_in_block;          // per block, per element
  TagIndex first_with_tag(n);
  bool warned_no_entity = false;

  // Consecutive elements nearly always share type and entity: remember the last lookups.
  std::uint64_t last_entity_key = ~0ull, last_block_key = ~0ull;
  std::size_t last_block = 0;
  int last_physical = 0;
  auto add_physical = [&](const ElementType& type, int elementary, int physical) {
    const std::uint64_t key = pack(type.dim, elementary);
    if (key == last_entity_key && physical == last_physical) return;
    if (elementary == 0) {
      if (physical != 0 && !warned_no_entity) {
        warned_no_entity = true;
        state.warn("physical tags of elements with elementary tag 0 were dropped");
      }
      return;
    }
    auto [it, added] = entity_of.try_emplace(pack(type.dim, elementary), mesh.entities.size());
    if (added) {
      Entity e;
      e.dim = type.dim;
      e.tag = elementary;
      mesh.entities.push_back(std::move(e));
    }
    std::vector<int>& tags = mesh.entities[it->second].physical_tags;
    if (physical != 0 && std::find(tags.begin(), tags.end(), physical) == tags.end()) tags.push_back(physical);
    last_entity_key = key;
    last_physical = physical;
  };

  for (std::size_t i = 0; i < n; ++i) {
    const Msh22Element& el = state.elements22[i];
    const std::uint32_t earlier = first_with_tag.find(el.tag);
    if (earlier != TagIndex::kMissing) {
      const Msh22Element& other = state.elements22[earlier];
      const auto a = nodes_of(i), b = nodes_of(earlier);
      if (other.type != el.type || other.elementary != el.elementary || !std::equal(a.begin(), a.end(), b.begin()))
        fail(i, fmt::format("element tag {} appears twice with a different type, entity or nodes", el.tag));
      add_physical(*el.type, el.elementary, el.physical);  // the same element in another group
      continue;
    }
    first_with_tag.insert(el.tag, static_cast<std::uint32_t>(i));
    const std::uint64_t block_key = pack(el.type->gmsh_id, el.elementary);
    if (block_key != last_block_key) {
      auto [it, added] = block_of.try_emplace(block_key, mesh.blocks.size());
      if (added) {
        ElementBlock block;
        block.type = el.type;
        block.entity_dim = el.type->dim;
        block.entity_tag = el.elementary;
        mesh.blocks.push_back(std::move(block));
        physicals_in_block.emplace_back();
      }
      last_block_key = block_key;
      last_block = it->second;
    }
    ElementBlock& block = mesh.blocks[last_block];
    block.tags.push_back(el.tag);
    const auto nodes = nodes_of(i);
    block.nodes.insert(block.nodes.end(), nodes.begin(), nodes.end());
    physicals_in_block[last_block].push_back(el.physical);
    add_physical(*el.type, el.elementary, el.physical);
  }

  // Gmsh writes an element of an entity with several physical groups once per group, under
  // fresh tags: a later element with the same nodes and another physical tag is such a copy.
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
    ElementBlock& block = mesh.blocks[b];
    if (block.entity_tag == 0) continue;
    const Entity& entity = mesh.entities[entity_of.at(pack(block.type->dim, block.entity_tag))];
    if (entity.physical_tags.size() < 2) continue;
    const std::size_t nn = static_cast<std::size_t>(block.type->num_nodes);
    std::unordered_multimap<std::uint64_t, std::size_t> by_hash;
    std::vector<std::size_t> keep;
    const std::vector<int>& physical = physicals_in_block[b];
    for (std::size_t e = 0; e < block.size(); ++e) {
      const auto nodes = block.element(e);
      std::uint64_t h = 1469598103934665603ull;
      for (NodeIndex v : nodes) h = (h ^ v) * 1099511628211ull;
      bool copy = false;
      auto range = by_hash.equal_range(h);
      for (auto it = range.first; it != range.second && !copy; ++it) {
        const auto other = block.element(it->second);
        copy = physical[it->second] != physical[e] && std::equal(nodes.begin(), nodes.end(), other.begin());
      }
      if (copy) continue;
      by_hash.emplace(h, e);
      keep.push_back(e);
    }
    if (keep.size() == block.size()) continue;
    std::vector<Tag> tags;
    std::vector<NodeIndex> nodes;
    tags.reserve(keep.size());
    nodes.reserve(keep.size() * nn);
    for (std::size_t e : keep) {
      tags.push_back(block.tags[e]);
      const auto el = block.element(e);
      nodes.insert(nodes.end(), el.begin(), el.end());
    }
    block.tags = std::move(tags);
    block.nodes = std::move(nodes);
  }
  state.elements22.clear();
  state.nodes22.clear();
}

}  // namespace quadval::io
