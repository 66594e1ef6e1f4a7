#pragma once
// Reads fixed-width native-endian values from a file held in memory; every error names the
// byte offset. The MSH binary readers check the endianness marker before using it.

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "io/file_bytes.hpp"
#include "quadval/error.hpp"

namespace quadval::io {

class ByteCursor {
 public:
  /// `source`, when given, owns `data` and gets the parsed pages back (release_parsed).
  ByteCursor(std::string_view data, std::string file, std::size_t pos, FileBytes* source = nullptr)
      : data_(data), file_(std::move(file)), pos_(pos), source_(source) {}

  const std::string& file() const noexcept { return file_; }
  std::size_t position() const noexcept { return pos_; }
  std::size_t remaining() const noexcept { return data_.size() - pos_; }

  std::int32_t i32(std::string_view what) { return read<std::int32_t>(what); }
  std::uint64_t u64(std::string_view what) { return read<std::uint64_t>(what); }
  double f64(std::string_view what) { return read<double>(what); }
  float f32(std::string_view what) { return read<float>(what); }
  std::uint16_t u16(std::string_view what) { return read<std::uint16_t>(what); }
  std::uint32_t u32(std::string_view what) { return read<std::uint32_t>(what); }

  /// Fails unless `count` items of `bytes_each` bytes fit in the rest of the file.
  void require(std::uint64_t count, std::uint64_t bytes_each, std::string_view what) const {
    if (bytes_each != 0 && count > remaining() / bytes_each)
      fail_here("the file is too short for " + std::to_string(count) + " " + std::string(what) +
                " (" + std::to_string(bytes_each) + " bytes each, " + std::to_string(remaining()) +
                " bytes left)");
  }

  [[noreturn]] void fail_here(const std::string& message) const {
    throw InputError::at_offset(file_, static_cast<long long>(pos_), message);
  }
  [[noreturn]] void fail_at(std::size_t pos, const std::string& message) const {
    throw InputError::at_offset(file_, static_cast<long long>(pos), message);
  }
  /// Now and then gives the pages already parsed back to the OS (FileBytes).
  void release_parsed() noexcept {
    if (source_ != nullptr && pos_ >= next_release_) {
      source_->release_before(pos_);
      next_release_ = pos_ + kReleaseEvery;
    }
  }
  /// Offset of the value read last.
  std::size_t last_position() const noexcept { return last_; }

 private:
  template <class T>
  T read(std::string_view what) {
    if (sizeof(T) > remaining())
      fail_here("unexpected end of file, expected " + std::string(what) + " (" +
                std::to_string(sizeof(T)) + " bytes)");
    T v;
    std::memcpy(&v, data_.data() + pos_, sizeof(T));
    last_ = pos_;
    pos_ += sizeof(T);
    return v;
  }

  std::string_view data_;
  std::string file_;
  std::size_t pos_;
  std::size_t last_ = 0;
  FileBytes* source_ = nullptr;
  std::size_t next_release_ = kReleaseEvery;
};

}  // namespace quadval::io
