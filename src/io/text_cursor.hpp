#pragma once
// A forward-only tokenizer over a file held in memory, with line tracking for error
// messages. Tokens are separated by blanks and line ends; numbers are parsed with
// std::from_chars (no locale, no per-token allocation), which is what keeps reading
// millions of elements near one second.

#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

#include "io/file_bytes.hpp"
#include "quadval/error.hpp"

namespace quadval::io {

class TextCursor {
 public:
  /// `source`, when given, owns `data` and gets the parsed pages back (release_parsed).
  TextCursor(std::string_view data, std::string file, FileBytes* source = nullptr)
      : data_(data), file_(std::move(file)), source_(source) {}

  const std::string& file() const noexcept { return file_; }
  std::string_view data() const noexcept { return data_; }
  FileBytes* source() const noexcept { return source_; }
  std::size_t position() const noexcept { return pos_; }
  std::size_t remaining() const noexcept { return data_.size() - pos_; }
  long line() const noexcept { return line_; }

  /// Moves to `pos` (after binary data, whose lines are not counted); errors then name byte
  /// offsets instead of lines.
  void jump_to(std::size_t pos) noexcept {
    pos_ = pos;
    offsets_only_ = true;
  }
  /// Moves forward to `pos`, counting the lines passed.
  void advance_to(std::size_t pos) noexcept {
    for (std::size_t i = pos_; i < pos; ++i) line_ += data_[i] == '\n';
    pos_ = pos;
  }
  /// A position to come back to (rewind), with its line.
  struct Mark {
    std::size_t pos;
    long line;
  };
  Mark mark() const noexcept { return {pos_, line_}; }
  /// Back to `m` (bytes given back by release_parsed come again from the file: a read-only
  /// private mapping, FileBytes).
  void rewind(const Mark& m) noexcept {
    pos_ = m.pos;
    line_ = m.line;
  }
  /// Moves forward to `pos`, which is `line_ends` line ends further (known to the caller).
  void skip_lines_to(std::size_t pos, long line_ends) noexcept {
    pos_ = pos;
    line_ += line_ends;
  }
  /// Errors name byte offsets from now on (the ASCII parts of a binary file).
  void report_offsets() noexcept { offsets_only_ = true; }

  /// Skips blanks and line ends; true if nothing but blanks remains.
  bool at_end() noexcept {
    skip_space();
    return pos_ >= data_.size();
  }

  void skip_space() noexcept {
    const char* p = data_.data() + pos_;
    const char* end = data_.data() + data_.size();
    while (p < end && is_space(*p)) {
      if (*p == '\n') ++line_;
      ++p;
    }
    pos_ = static_cast<std::size_t>(p - data_.data());
  }

  /// Next token; fails at end of file with "expected <what>".
  std::string_view token(std::string_view what) {
    skip_space();
    token_line_ = line_;
    token_pos_ = pos_;
    if (pos_ >= data_.size()) {
      // Name the last line of the file, not the empty one after its final line end.
      if (line_ > 1 && !data_.empty() && data_.back() == '\n') token_line_ = line_ - 1;
      fail_at_token("unexpected end of file, expected " + std::string(what));
    }
    std::size_t end = pos_;
    while (end < data_.size() && !is_space(data_[end])) ++end;
    std::string_view t = data_.substr(pos_, end - pos_);
    pos_ = end;
    return t;
  }

  /// Next token, which must be `word`.
  void expect(std::string_view word) {
    std::string_view t = token(word);
    if (t != word) fail_at_token("expected " + std::string(word) + ", found '" + shorten(t) + "'");
  }

  /// A signed integer in [lo, hi].
  std::int64_t integer(std::string_view what, std::int64_t lo = std::numeric_limits<std::int64_t>::min(),
                       std::int64_t hi = std::numeric_limits<std::int64_t>::max()) {
    std::string_view t = token(what);
    std::int64_t v = 0;
    auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (ec != std::errc() || ptr != t.data() + t.size())
      fail_at_token("expected " + std::string(what) + " (an integer), found '" + shorten(t) + "'");
    if (v < lo || v > hi)
      fail_at_token(std::string(what) + " " + std::string(t) + " is out of range [" +
                    std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v;
  }

  /// An unsigned integer (counts and tags).
  std::uint64_t unsigned_integer(std::string_view what) {
    std::string_view t = token(what);
    std::uint64_t v = 0;
    if (!parse_unsigned(t, v))
      fail_at_token("expected " + std::string(what) + " (a non-negative integer), found '" +
                    shorten(t) + "'");
    return v;
  }

  /// A finite floating-point number.
  double real(std::string_view what) {
    std::string_view t = token(what);
    double v = 0;
    switch (parse_real(t, v)) {
      case RealToken::ok: return v;
      case RealToken::out_of_range:
        fail_at_token(std::string(what) + " '" + shorten(t) + "' is out of the range of double");
      case RealToken::not_a_number:
        fail_at_token("expected " + std::string(what) + " (a number), found '" + shorten(t) + "'");
      case RealToken::not_finite: break;
    }
    fail_at_token(std::string(what) + " is '" + shorten(t) + "', expected a finite number");
  }

  /// How unsigned_integer reads a token: all of it, digits only. (Shared with the
  /// parallel reader, parallel_lines.hpp, which must accept exactly what this does.)
  static bool parse_unsigned(std::string_view t, std::uint64_t& v) noexcept {
    const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    return ec == std::errc() && ptr == t.data() + t.size();
  }
  /// How real reads a token: an optional '+' (from_chars rejects it), then all of it, a
  /// finite double.
  enum class RealToken { ok, not_a_number, out_of_range, not_finite };
  static RealToken parse_real(std::string_view t, double& v) noexcept {
    const char* first = t.data();
    const char* last = t.data() + t.size();
    if (first < last && *first == '+') ++first;
    const auto [ptr, ec] = std::from_chars(first, last, v);
    if (ec == std::errc::result_out_of_range) return RealToken::out_of_range;
    if (ec != std::errc() || ptr != last) return RealToken::not_a_number;
    return std::isfinite(v) ? RealToken::ok : RealToken::not_finite;
  }

  /// The rest of the current line (without the line end); moves to the next line.
  std::string_view rest_of_line() noexcept {
    std::size_t end = data_.find('\n', pos_);
    if (end == std::string_view::npos) end = data_.size();
    std::string_view t = data_.substr(pos_, end - pos_);
    if (!t.empty() && t.back() == '\r') t.remove_suffix(1);
    pos_ = end < data_.size() ? end + 1 : end;
    if (end < data_.size()) ++line_;
    return t;
  }

  /// Consumes blanks up to and including the next line end; fails if anything else is on
  /// the line. Used before binary data, which starts right after the line end.
  void finish_line(std::string_view what) {
    while (pos_ < data_.size() && is_trailing_blank(data_[pos_])) ++pos_;
    if (pos_ >= data_.size()) fail_here("unexpected end of file, expected a line end before " + std::string(what));
    if (data_[pos_] != '\n') fail_here("expected a line end before " + std::string(what) + ", found '" + shorten(data_.substr(pos_, 20)) + "'");
    ++pos_;
    ++line_;
  }

  /// Starts a record that must sit on one line (an element line, say).
  void begin_record() noexcept {
    skip_space();
    record_line_ = line_;
    release_parsed();
  }
  /// Now and then gives the pages already parsed back to the OS (FileBytes).
  void release_parsed() noexcept {
    if (source_ != nullptr && pos_ >= next_release_) {
      source_->release_before(pos_);
      next_release_ = pos_ + kReleaseEvery;
    }
  }
  /// Checks that the record's tokens were all on its line and nothing else follows.
  void end_record(std::string_view what) {
    if (line_ != record_line_)
      fail_line(record_line_, "too few values on the line, expected " + std::string(what));
    std::size_t p = pos_;
    while (p < data_.size() && is_trailing_blank(data_[p])) ++p;
    if (p < data_.size() && data_[p] != '\n') {
      token_line_ = line_;
      fail_at_token("too many values on the line, expected " + std::string(what));
    }
  }

  /// Fails at the last token read (its line, or its byte offset in binary files).
  [[noreturn]] void fail_at_token(const std::string& message) const {
    if (offsets_only_) throw InputError::at_offset(file_, static_cast<long long>(token_pos_), message);
    throw InputError::at_line(file_, token_line_, message);
  }
  /// Fails at the current position.
  [[noreturn]] void fail_here(const std::string& message) const {
    if (offsets_only_) throw InputError::at_offset(file_, static_cast<long long>(pos_), message);
    throw InputError::at_line(file_, line_, message);
  }
  [[noreturn]] void fail_line(long line, const std::string& message) const {
    if (offsets_only_) throw InputError::at_offset(file_, static_cast<long long>(token_pos_), message);
    throw InputError::at_line(file_, line, message);
  }

  /// At most 40 characters of `s`, for messages.
  static std::string shorten(std::string_view s) {
    std::string r(s.substr(0, 40));
    for (char& c : r)
      if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
    if (s.size() > 40) r += "...";
    return r;
  }

  static bool is_space(char c) noexcept {
    return c == ' ' || c == '\n' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
  }
  /// What end_record and finish_line allow after a line's last value.
  static bool is_trailing_blank(char c) noexcept { return c == ' ' || c == '\t' || c == '\r'; }

 private:
  std::string_view data_;
  std::string file_;
  std::size_t pos_ = 0;
  long line_ = 1;
  long token_line_ = 1;
  std::size_t token_pos_ = 0;
  long record_line_ = 1;
  bool offsets_only_ = false;
  FileBytes* source_ = nullptr;
  std::size_t next_release_ = kReleaseEvery;
};

}  // namespace quadval::io
