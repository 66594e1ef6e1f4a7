// Large blocks' element and coordinate lines on several threads (see the header).
#include "io/parallel_lines.hpp"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <optional>
#include <string_view>
#include <utility>

#include "quadval/element_type.hpp"

namespace quadval::io {
namespace {

// Token separators within a line: TextCursor::is_space but the line end.
bool is_blank(char c) noexcept { return c != '\n' && TextCursor::is_space(c); }

// The next blank-separated token of [p, last), p moved past it; empty at the line's end.
std::string_view next_token(const char*& p, const char* last) noexcept {
  while (p < last && is_blank(*p)) ++p;
  const char* first = p;
  while (p < last && !is_blank(*p)) ++p;
  return {first, static_cast<std::size_t>(p - first)};
}

bool next_unsigned(const char*& p, const char* last, std::uint64_t& v) noexcept {
  const std::string_view t = next_token(p, last);
  return !t.empty() && TextCursor::parse_unsigned(t, v);
}

bool next_real(const char*& p, const char* last, double& v) noexcept {
  const std::string_view t = next_token(p, last);
  return !t.empty() && TextCursor::parse_real(t, v) == TextCursor::RealToken::ok;
}

// Nothing but token separators up to the line's end (tag and coordinate lines are read
// token by token, across line ends).
bool only_blanks(const char* p, const char* last) noexcept {
  while (p < last && is_blank(*p)) ++p;
  return p == last;
}

// Only what TextCursor::end_record allows after a record's last value (element lines).
bool record_ends(const char* p, const char* last) noexcept {
  while (p < last && TextCursor::is_trailing_blank(*p)) ++p;
  return p == last;
}

// [begin, end) of the `count` lines after the cursor's line, whose rest must be blank:
// begin after its line end, end after the count-th line end from there.
std::optional<std::pair<std::size_t, std::size_t>> next_lines(const TextCursor& in, std::uint64_t count) {
  const std::string_view data = in.data();
  std::size_t p = in.position();
  while (p < data.size() && is_blank(data[p])) ++p;
  if (p >= data.size() || data[p] != '\n') return std::nullopt;
  const std::size_t begin = p + 1;
  // Line ends counted a block at a time (a vectorised count), then found one by one in
  // the block that holds the last.
  constexpr std::size_t kBlock = std::size_t{1} << 16;
  std::size_t at = begin;
  std::uint64_t left = count;
  while (left > 0) {
    if (at >= data.size()) return std::nullopt;
    const std::size_t stop = std::min(data.size(), at + kBlock);
    const auto ends = static_cast<std::uint64_t>(std::count(data.data() + at, data.data() + stop, '\n'));
    if (ends < left) {
      left -= ends;
      at = stop;
      continue;
    }
    for (; left > 0; --left)
      at = static_cast<std::size_t>(static_cast<const char*>(std::memchr(data.data() + at, '\n', stop - at)) - data.data()) + 1;
  }
  return std::pair{begin, at};
}

// Calls parse(first, last, i) for line i (0 .. count - 1, [first, last) without its line
// end) of the `count` lines after the cursor's line, the lines cut into one run per
// thread; the end of those lines when every call returned true. The cursor stays.
template <class Parse>
std::optional<std::size_t> parse_lines_here(const TextCursor& in, std::uint64_t count, const Parse& parse) {
  if (count < kParallelLines) return std::nullopt;
  const auto run = next_lines(in, count);
  if (!run) return std::nullopt;
  const auto [begin, end] = *run;
  const char* base = in.data().data();
  const auto pieces = static_cast<std::size_t>(
      std::clamp<std::uint64_t>(count / kParallelLines, 1, static_cast<std::uint64_t>(std::max(1, omp_get_max_threads()))));
  // Cuts at line starts, about equal in bytes.
  std::vector<std::size_t> cut(pieces + 1, end);
  cut[0] = begin;
  for (std::size_t k = 1; k < pieces; ++k) {
    const std::size_t at = std::max(cut[k - 1], begin + (end - begin) / pieces * k);
    const void* line_end = std::memchr(base + at, '\n', end - at);
    cut[k] = line_end == nullptr ? end : static_cast<std::size_t>(static_cast<const char*>(line_end) - base) + 1;
  }
  std::vector<std::uint64_t> first_line(pieces + 1, 0);
  std::atomic<bool> ok{true};
#pragma omp parallel num_threads(static_cast<int>(pieces))
  {
#pragma omp for schedule(static, 1)
    for (std::size_t k = 0; k < pieces; ++k)
      first_line[k + 1] = static_cast<std::uint64_t>(std::count(base + cut[k], base + cut[k + 1], '\n'));
#pragma omp single
    for (std::size_t k = 0; k < pieces; ++k) first_line[k + 1] += first_line[k];
#pragma omp for schedule(static, 1)
    for (std::size_t k = 0; k < pieces; ++k) {
      std::uint64_t i = first_line[k];
      for (const char* p = base + cut[k]; p < base + cut[k + 1] && ok.load(std::memory_order_relaxed); ++i) {
        const char* line_end = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(base + cut[k + 1] - p)));
        if (!parse(p, line_end, i)) ok.store(false, std::memory_order_relaxed);
        p = line_end + 1;
      }
    }
  }
  if (!ok.load()) return std::nullopt;
  return end;
}

// The same, and then the cursor at the end of the last line (before its line end), where
// reading its last value one by one leaves it.
template <class Parse>
bool parse_lines(TextCursor& in, std::uint64_t count, const Parse& parse) {
  const auto end = parse_lines_here(in, count, parse);
  if (!end) return false;
  in.skip_lines_to(*end - 1, static_cast<long>(count));
  in.release_parsed();
  return true;
}

// A positive MSH 2.2 int (what AsciiSource::int32 reads, within [1, 2^31 - 1]).
bool next_positive_int(const char*& p, const char* last, std::uint64_t& v) noexcept {
  return next_unsigned(p, last, v) && v >= 1 && v <= 0x7fffffffu;
}

// The head of a MSH 2.2 element line: "tag type number-of-tags tags...", all positive but
// the count of tags (0 to 1000, as read_element22_tags allows) and the tags (>= 0).
struct Element22Head {
  std::uint64_t tag = 0;
  const ElementType* type = nullptr;
  int physical = 0, elementary = 0;
  bool partitions = false;  // more than two tags
};
bool next_element22_head(const char*& p, const char* last, Element22Head& h) noexcept {
  std::uint64_t id = 0, num_tags = 0;
  if (!next_positive_int(p, last, h.tag) || !next_positive_int(p, last, id) || id > 1000 ||
      !next_unsigned(p, last, num_tags) || num_tags > 1000)
    return false;
  h.type = find_element_type(static_cast<int>(id));
  if (h.type == nullptr || h.type->num_nodes == 0) return false;
  h.physical = h.elementary = 0;
  for (std::uint64_t k = 0; k < num_tags; ++k) {
    std::uint64_t v = 0;
    if (!next_unsigned(p, last, v) || v > 0x7fffffffu) return false;
    if (k == 0) h.physical = static_cast<int>(v);
    if (k == 1) h.elementary = static_cast<int>(v);
  }
  h.partitions = num_tags > 2;
  return true;
}

}  // namespace

bool read_element_lines(TextCursor& in, std::uint64_t count, std::uint64_t nodes_each, const TagIndex& index,
                        std::vector<Tag>& tags, std::vector<NodeIndex>& nodes) {
  if (count < kParallelLines) return false;
  const std::size_t tags_before = tags.size(), nodes_before = nodes.size();
  tags.resize(tags_before + count);
  nodes.resize(nodes_before + count * nodes_each);
  Tag* tag_out = tags.data() + tags_before;
  NodeIndex* node_out = nodes.data() + nodes_before;
  const bool ok = parse_lines(in, count, [&](const char* p, const char* last, std::uint64_t i) {
    if (!next_unsigned(p, last, tag_out[i])) return false;
    NodeIndex* out = node_out + i * nodes_each;
    for (std::uint64_t k = 0; k < nodes_each; ++k) {
      std::uint64_t node_tag = 0;
      if (!next_unsigned(p, last, node_tag)) return false;
      out[k] = index.find(node_tag);
      if (out[k] == TagIndex::kMissing) return false;
    }
    return record_ends(p, last);
  });
  if (!ok) {
    tags.resize(tags_before);
    nodes.resize(nodes_before);
  }
  return ok;
}

bool read_tag_lines(TextCursor& in, std::uint64_t count, std::vector<Tag>& tags) {
  if (count < kParallelLines) return false;
  const std::size_t before = tags.size();
  tags.resize(before + count);
  Tag* out = tags.data() + before;
  const bool ok = parse_lines(in, count, [&](const char* p, const char* last, std::uint64_t i) {
    return next_unsigned(p, last, out[i]) && only_blanks(p, last);
  });
  if (!ok) tags.resize(before);
  return ok;
}

bool read_coordinate_lines(TextCursor& in, std::uint64_t count, std::vector<double>& coords) {
  if (count < kParallelLines) return false;
  const std::size_t before = coords.size();
  coords.resize(before + 3 * count);
  double* out = coords.data() + before;
  const bool ok = parse_lines(in, count, [&](const char* p, const char* last, std::uint64_t i) {
    double* xyz = out + 3 * i;
    return next_real(p, last, xyz[0]) && next_real(p, last, xyz[1]) && next_real(p, last, xyz[2]) &&
           only_blanks(p, last);
  });
  if (!ok) coords.resize(before);
  return ok;
}

bool read_node22_lines(TextCursor& in, std::uint64_t count, std::vector<Tag>& tags, std::vector<double>& coords) {
  if (count < kParallelLines) return false;
  const std::size_t tags_before = tags.size(), coords_before = coords.size();
  tags.resize(tags_before + count);
  coords.resize(coords_before + 3 * count);
  Tag* tag_out = tags.data() + tags_before;
  double* xyz_out = coords.data() + coords_before;
  const bool ok = parse_lines(in, count, [&](const char* p, const char* last, std::uint64_t i) {
    double* xyz = xyz_out + 3 * i;
    return next_positive_int(p, last, tag_out[i]) && next_real(p, last, xyz[0]) && next_real(p, last, xyz[1]) &&
           next_real(p, last, xyz[2]) && record_ends(p, last);
  });
  if (!ok) {
    tags.resize(tags_before);
    coords.resize(coords_before);
  }
  return ok;
}

bool read_element22_lines(TextCursor& in, std::uint64_t count, MshReadState& state) {
  if (count < kParallelLines) return false;
  // Two passes, as the node count of a line shows only from its type: the heads and node
  // counts, then (at offsets summed in between, from where each head ended) the nodes.
  const std::size_t before = state.elements22.size(), nodes_before = state.nodes22.size();
  state.elements22.resize(before + count);
  state.positions22.resize(before + count);
  std::vector<std::size_t> offset(count + 1, 0);
  std::vector<std::size_t> head_bytes(count);
  Msh22Element* element_out = state.elements22.data() + before;
  std::atomic<bool> partitions{false};
  const auto restore = [&] {
    state.elements22.resize(before);
    state.positions22.resize(before);
    state.nodes22.resize(nodes_before);
    return false;
  };
  const bool heads = parse_lines_here(in, count, [&](const char* p, const char* last, std::uint64_t i) {
    const char* first = p;
    Element22Head h;
    if (!next_element22_head(p, last, h)) return false;
    head_bytes[i] = static_cast<std::size_t>(p - first);
    element_out[i] = {h.tag, h.type, h.physical, h.elementary};
    offset[i + 1] = static_cast<std::size_t>(h.type->num_nodes);
    if (h.partitions) partitions.store(true, std::memory_order_relaxed);
    return true;
  }).has_value();
  if (!heads) return restore();
  offset[0] = nodes_before;
  for (std::uint64_t i = 0; i < count; ++i) offset[i + 1] += offset[i];
  state.nodes22.resize(offset[count]);
  NodeIndex* nodes = state.nodes22.data();
  const TagIndex& index = state.node_index;
  // The first line is the one after the cursor's (parse_lines checks the rest is blank).
  const auto first_line = static_cast<std::size_t>(in.line()) + 1;
  const bool ok = parse_lines(in, count, [&](const char* p, const char* last, std::uint64_t i) {
    p += head_bytes[i];
    for (std::size_t k = offset[i]; k < offset[i + 1]; ++k) {
      std::uint64_t node_tag = 0;
      if (!next_positive_int(p, last, node_tag)) return false;
      nodes[k] = index.find(node_tag);
      if (nodes[k] == TagIndex::kMissing) return false;
    }
    return record_ends(p, last);
  });
  if (!ok) return restore();
  state.nodes22_offset.resize(before + count);
  for (std::uint64_t i = 0; i < count; ++i) {
    state.nodes22_offset[before + i] = offset[i];
    state.positions22[before + i] = first_line + i;
  }
  if (partitions.load() && !state.warned_partitions) {
    state.warned_partitions = true;
    state.warn("MSH 2.2 partition tags are not used and were dropped");
  }
  return true;
}

}  // namespace quadval::io
