// ASCII MSH sections: the shared templates of msh_sections.hpp over a token source.
#include "io/msh_sections.hpp"

namespace quadval::io {

void read_entities41_ascii(TextCursor& in, MshReadState& state) {
  AsciiSource src{in};
  read_entities41(src, state);
}

void read_nodes41_ascii(TextCursor& in, MshReadState& state) {
  AsciiSource src{in};
  read_nodes41(src, state);
}

void read_elements41_ascii(TextCursor& in, MshReadState& state) {
  AsciiSource src{in};
  read_elements41(src, state);
}

void read_nodes22_ascii(TextCursor& in, MshReadState& state) {
  AsciiSource src{in};
  read_nodes22(src, state, in.unsigned_integer("number of nodes"));
}

void read_elements22_ascii(TextCursor& in, MshReadState& state) {
  if (!state.have_nodes) in.fail_here("$Elements comes before $Nodes");
  AsciiSource src{in};
  const std::uint64_t count = in.unsigned_integer("number of elements");
  src.require(count, 4, 0, "elements");
  state.elements22.reserve(static_cast<std::size_t>(count));
  state.nodes22_offset.reserve(static_cast<std::size_t>(count));
  state.positions22.reserve(static_cast<std::size_t>(count));
  if (read_element22_lines(in, count, state)) {
    state.have_elements = true;
    return;
  }
  for (std::uint64_t e = 0; e < count; ++e) {
    src.begin_record();
    const std::int32_t tag = src.int32("element tag");
    if (tag < 1) src.fail(fmt::format("element tag {}, expected a tag >= 1", tag));
    const std::size_t line = static_cast<std::size_t>(in.line());
    const ElementType& type = element_type_or_fail(src, src.int32("element type"));
    std::int32_t physical = 0, elementary = 0;
    read_element22_tags(src, state, src.int32("number of element tags"), physical, elementary);
    read_element22_nodes(src, state, type, static_cast<std::uint64_t>(tag), physical, elementary, line);
    src.end_record(fmt::format("tag, type, tags and {} node tags ({})", type.num_nodes, type.name));
  }
  state.have_elements = true;
}

}  // namespace quadval::io
