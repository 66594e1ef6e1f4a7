#pragma once
/// Errors: exceptions for the user's input, assertions for our own bugs (STYLE.md §10).

#include <sstream>
#include <stdexcept>
#include <string>

namespace quadval {

/// Bad input: carries the file and where in it (line, byte offset, element) it went wrong.
/// what() reads "FILE:LINE: message", "FILE: byte offset N: message" or "FILE: message".
class InputError : public std::runtime_error {
 public:
  static InputError at_line(const std::string& file, long line, const std::string& message);
  static InputError at_offset(const std::string& file, long long offset,
                              const std::string& message);
  static InputError in_element(const std::string& file, unsigned long long element_tag,
                               const std::string& message);
  static InputError in_file(const std::string& file, const std::string& message);

  const std::string& file() const noexcept { return file_; }
  const std::string& message() const noexcept { return message_; }

 private:
  InputError(std::string full, std::string file, std::string message)
      : std::runtime_error(std::move(full)), file_(std::move(file)), message_(std::move(message)) {}
  std::string file_;
  std::string message_;
};

/// A violated internal invariant: a bug in quadval, never the user's fault.
class InternalError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

}  // namespace quadval

/// Cheap invariant check, always on.
#define QV_ASSERT(cond, msg)                                                             \
  do {                                                                                   \
    if (!(cond)) {                                                                       \
      std::ostringstream qv_assert_os_;                                                  \
      qv_assert_os_ << __FILE__ << ":" << __LINE__ << ": assertion `" #cond "` failed: " \
                    << msg;                                                              \
      throw ::quadval::InternalError(qv_assert_os_.str());                               \
    }                                                                                    \
  } while (0)

/// Expensive invariant check, debug builds only.
#ifndef NDEBUG
#define QV_DEBUG_ASSERT(cond, msg) QV_ASSERT(cond, msg)
#else
#define QV_DEBUG_ASSERT(cond, msg) \
  do {                             \
  } while (0)
#endif
