// Binary MSH sections: the shared templates of msh_sections.hpp over fixed-width values,
// plus the grouped element layout of MSH 2.2 binary files.
#include "io/msh_sections.hpp"

namespace quadval::io {

namespace {

/// Runs `read` on the binary data that starts at in.position(), then moves `in` past it.
template <class Read>
void read_binary(TextCursor& in, Read&& read) {
  ByteCursor bytes(in.data(), in.file(), in.position(), in.source());
  BinarySource src{bytes};
  read(src);
  in.jump_to(bytes.position());
}

}  // namespace

void read_entities41_binary(TextCursor& in, MshReadState& state) {
  read_binary(in, [&](BinarySource& src) { read_entities41(src, state); });
}

void read_nodes41_binary(TextCursor& in, MshReadState& state) {
  read_binary(in, [&](BinarySource& src) { read_nodes41(src, state); });
}

void read_elements41_binary(TextCursor& in, MshReadState& state) {
  read_binary(in, [&](BinarySource& src) { read_elements41(src, state); });
}

void read_nodes22_binary(TextCursor& in, MshReadState& state) {
  const std::uint64_t count = in.unsigned_integer("number of nodes");
  in.finish_line("binary node data");
  read_binary(in, [&](BinarySource& src) { read_nodes22(src, state, count); });
}

// Binary 2.2 elements come in groups: a header (type, number of elements, number of
// tags), then each element as int tag, int tags..., int node tags...
void read_elements22_binary(TextCursor& in, MshReadState& state) {
  if (!state.have_nodes) in.fail_here("$Elements comes before $Nodes");
  const std::uint64_t count = in.unsigned_integer("number of elements");
  in.finish_line("binary element data");
  read_binary(in, [&](BinarySource& src) {
    src.require(count, 1, 8, "elements");
    state.elements22.reserve(static_cast<std::size_t>(count));
    state.nodes22_offset.reserve(static_cast<std::size_t>(count));
    state.positions22.reserve(static_cast<std::size_t>(count));
    std::uint64_t done = 0;
    while (done < count) {
      const ElementType& type = element_type_or_fail(src, src.int32("element type"));
      const std::int32_t group = src.int32("number of elements in the group");
      const std::int32_t num_tags = src.int32("number of element tags");
      if (group < 1 || static_cast<std::uint64_t>(group) > count - done)
        src.fail(fmt::format("group of {} elements, expected 1 to the {} elements left", group,
                             count - done));
      if (num_tags < 0 || num_tags > 1000)
        src.fail(fmt::format("number of element tags is {}, expected 0 to 1000", num_tags));
      src.require(static_cast<std::uint64_t>(group),
                  1, 4 * (1 + static_cast<std::uint64_t>(num_tags) + static_cast<std::uint64_t>(type.num_nodes)),
                  "elements");
      for (std::int32_t e = 0; e < group; ++e) {
        src.release_parsed();
        const std::size_t where = src.where();
        const std::int32_t tag = src.int32("element tag");
        if (tag < 1) src.fail(fmt::format("element tag {}, expected a tag >= 1", tag));
        std::int32_t physical = 0, elementary = 0;
        read_element22_tags(src, state, num_tags, physical, elementary);
        read_element22_nodes(src, state, type, static_cast<std::uint64_t>(tag), physical, elementary, where);
      }
      done += static_cast<std::uint64_t>(group);
    }
  });
  state.have_elements = true;
}

}  // namespace quadval::io
