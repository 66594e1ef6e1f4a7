#pragma once
// Internal interface of the MSH readers. msh_read.cpp parses $MeshFormat and dispatches
// sections; the ASCII and binary section readers (msh_read_ascii.cpp, msh_read_binary.cpp)
// share their logic through the templates of msh_sections.hpp.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "io/byte_cursor.hpp"
#include "io/tag_index.hpp"
#include "io/text_cursor.hpp"
#include "quadval/mesh.hpp"

namespace quadval::io {

/// One element of a MSH 2.2 file before grouping into blocks.
struct Msh22Element {
  std::uint64_t tag;
  const ElementType* type;
  int physical;
  int elementary;
};

/// What the readers build, and what they have seen so far.
struct MshReadState {
  std::string file;
  std::vector<std::string>* warnings = nullptr;  ///< never null inside the readers
  Mesh mesh;
  TagIndex node_index;    ///< node tag -> index in mesh.node_tags
  bool have_nodes = false;
  bool have_elements = false;
  bool have_entities = false;
  bool warned_parametric = false;
  bool warned_partitions = false;

  // MSH 2.2 only: elements in file order, their nodes, grouped in finish_msh22().
  std::vector<Msh22Element> elements22;
  std::vector<NodeIndex> nodes22;
  std::vector<std::size_t> nodes22_offset;  ///< start of each element's nodes in nodes22
  std::vector<std::size_t> positions22;     ///< where each element starts (line or offset)

  void warn(const std::string& message) { warnings->push_back(file + ": " + message); }
};

// MSH 4.1 sections.
void read_entities41_ascii(TextCursor& in, MshReadState& state);
void read_nodes41_ascii(TextCursor& in, MshReadState& state);
void read_elements41_ascii(TextCursor& in, MshReadState& state);
/// Binary readers start at in.position() (just after the section name's line) and leave
/// `in` just after the binary data.
void read_entities41_binary(TextCursor& in, MshReadState& state);
void read_nodes41_binary(TextCursor& in, MshReadState& state);
void read_elements41_binary(TextCursor& in, MshReadState& state);

// MSH 2.2 sections (elements are collected, then grouped by finish_msh22).
void read_nodes22_ascii(TextCursor& in, MshReadState& state);
void read_elements22_ascii(TextCursor& in, MshReadState& state);
void read_nodes22_binary(TextCursor& in, MshReadState& state);
void read_elements22_binary(TextCursor& in, MshReadState& state);
/// Groups the collected 2.2 elements into blocks and entities (io.hpp describes how).
/// `binary` chooses how positions22 are reported in errors.
void finish_msh22(MshReadState& state, bool binary);

/// Reads a whole MSH file (any supported version) held in `bytes`; `source`, when given,
/// owns `bytes` and gets the pages already parsed back as reading goes (FileBytes).
Mesh read_msh(std::string_view bytes, const std::string& file, std::vector<std::string>& warnings,
              FileBytes* source = nullptr);

}  // namespace quadval::io
