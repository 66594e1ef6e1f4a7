#pragma once
// Buffered output for the writers: text through fmt (shortest round-trip repr for
// doubles with "{}"), raw native-endian values for binary data; flushed in large chunks.

#include <cstdint>
#include <cstring>
#include <ostream>
#include <string_view>

#include <fmt/compile.h>
#include <fmt/format.h>

namespace quadval::io {

class OutBuffer {
 public:
  explicit OutBuffer(std::ostream& out) : out_(out) {}
  ~OutBuffer() = default;
  OutBuffer(const OutBuffer&) = delete;
  OutBuffer& operator=(const OutBuffer&) = delete;

  template <class... Args>
  void text(fmt::format_string<Args...> format, Args&&... args) {
    fmt::format_to(std::back_inserter(buf_), format, std::forward<Args>(args)...);
    maybe_flush();
  }
  void text(std::string_view s) {
    buf_.append(s.data(), s.data() + s.size());
    maybe_flush();
  }
  // The hot loops' pieces: the same characters as text("{}", v), without parsing a format
  // string or going through an output iterator per call (convert of 1M hexahedra: see
  // msh_write.cpp).
  void integer(std::uint64_t v) { append(fmt::format_int(v)); }
  void integer(std::int64_t v) { append(fmt::format_int(v)); }
  void integer(std::int32_t v) { append(fmt::format_int(v)); }
  void real(double v) {
    char digits[32];  // the shortest round-trip form is at most 24 characters
    append(digits, fmt::format_to(digits, FMT_COMPILE("{}"), v));
  }
  void put(char c) {
    buf_.push_back(c);
    maybe_flush();
  }
  template <class T>
  void raw(const T& value) {
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    buf_.append(bytes, bytes + sizeof(T));
    maybe_flush();
  }
  /// Copies `n` bytes into the buffer (small records).
  void bytes_buffered(const void* data, std::size_t n) {
    const char* p = static_cast<const char*>(data);
    buf_.append(p, p + n);
    maybe_flush();
  }
  /// Writes `n` bytes straight through (large arrays).
  void bytes(const void* data, std::size_t n) {
    flush();
    out_.write(static_cast<const char*>(data), static_cast<std::streamsize>(n));
  }
  /// Writes what is buffered; call at the end.
  void flush() {
    out_.write(buf_.data(), static_cast<std::streamsize>(buf_.size()));
    buf_.clear();
  }

 private:
  void append(const fmt::format_int& f) { append(f.data(), f.data() + f.size()); }
  void append(const char* first, const char* last) {
    buf_.append(first, last);
    maybe_flush();
  }
  void maybe_flush() {
    if (buf_.size() > (1u << 22)) flush();
  }
  std::ostream& out_;
  fmt::memory_buffer buf_;
};

}  // namespace quadval::io
