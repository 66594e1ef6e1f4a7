#include "quadval/error.hpp"

namespace quadval {

InputError InputError::at_line(const std::string& file, long line, const std::string& message) {
  return InputError(file + ":" + std::to_string(line) + ": " + message, file, message);
}

InputError InputError::at_offset(const std::string& file, long long offset,
                                 const std::string& message) {
  return InputError(file + ": byte offset " + std::to_string(offset) + ": " + message, file,
                    message);
}

InputError InputError::in_element(const std::string& file, unsigned long long element_tag,
                                  const std::string& message) {
  return InputError(file + ": element " + std::to_string(element_tag) + ": " + message, file,
                    message);
}

InputError InputError::in_file(const std::string& file, const std::string& message) {
  return InputError(file + ": " + message, file, message);
}

}  // namespace quadval
