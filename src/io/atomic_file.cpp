#include "quadval/atomic_file.hpp"

#include <fstream>
#include <random>
#include <string>

#include "quadval/error.hpp"

namespace quadval {

namespace {

std::filesystem::path temporary_name(const std::filesystem::path& path) {
  std::random_device rd;
  std::filesystem::path tmp = path;
  tmp += ".tmp" + std::to_string(rd() % 1000000);
  return tmp;
}

}  // namespace

void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write) {
  if (std::filesystem::is_directory(path))
    throw InputError::in_file(path.string(), "is a directory, expected an output file name");
  const std::filesystem::path tmp = temporary_name(path);
  try {
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      if (!out) throw InputError::in_file(path.string(), "cannot open for writing");
      write(out);
      out.flush();
      if (!out) throw InputError::in_file(path.string(), "write failed (disk full?)");
    }
    std::filesystem::rename(tmp, path);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw;
  }
}

}  // namespace quadval
