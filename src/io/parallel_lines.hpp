#pragma once
// The element and coordinate lines of a large ASCII MSH 4.1 block, and of a large MSH 2.2
// $Nodes or $Elements section, parsed on OpenMP's threads: they are nearly all of a large
// mesh's reading (1M hexahedra, 128 MB: 0.40 s on one thread, of which the element lines
// two thirds).
//
// Only the plain form that Gmsh writes takes this path: one record per line, every line a
// record, single values separated by blanks. At anything else (a blank line, a bad or
// missing value, an unknown node tag, a record across lines) it gives up, leaving the
// cursor and the output as they were, and the caller parses the lines one by one as
// before, which reports the error with its line. So what is accepted and every message
// stay as they were; values are read by TextCursor's own token rules
// (parse_unsigned, parse_real, is_trailing_blank at a record's end).

#include <cstdint>
#include <vector>

#include "io/msh_reader.hpp"
#include "io/tag_index.hpp"
#include "io/text_cursor.hpp"
#include "quadval/mesh.hpp"

namespace quadval::io {

/// Blocks of fewer lines are parsed one by one: a thread's start costs about 0.1 ms, and a
/// thousand lines take one thread about 30 us (node tags) to 250 us (hexahedra).
inline constexpr std::uint64_t kParallelLines = 8192;

/// The `count` lines after the cursor's line (the rest of which must be blank), each an
/// element tag and `nodes_each` node tags found in `index`: appends the tags to `tags` and
/// the node positions to `nodes`, moves the cursor past the lines and returns true; false
/// (nothing changed) where any line is not of that form, or count < kParallelLines.
bool read_element_lines(TextCursor& in, std::uint64_t count, std::uint64_t nodes_each, const TagIndex& index,
                        std::vector<Tag>& tags, std::vector<NodeIndex>& nodes);

/// The same for `count` lines of one node tag each, appended to `tags` (as read: tag 0 and
/// repeated tags are the caller's to find).
bool read_tag_lines(TextCursor& in, std::uint64_t count, std::vector<Tag>& tags);

/// The same for `count` lines of three finite coordinates each (TextCursor::real's
/// numbers), appended to `coords`.
bool read_coordinate_lines(TextCursor& in, std::uint64_t count, std::vector<double>& coords);

/// MSH 2.2: the same for `count` lines of a positive node tag and three coordinates each,
/// appended to `tags` and `coords` (repeated tags are the caller's to find).
bool read_node22_lines(TextCursor& in, std::uint64_t count, std::vector<Tag>& tags, std::vector<double>& coords);

/// MSH 2.2: the same for `count` element lines ("tag type number-of-tags tags... nodes...",
/// every node in state.node_index), appended to state's elements22, nodes22,
/// nodes22_offset and positions22 (their lines); warns, once, of partition tags.
bool read_element22_lines(TextCursor& in, std::uint64_t count, MshReadState& state);

}  // namespace quadval::io
