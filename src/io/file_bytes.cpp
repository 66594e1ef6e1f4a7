#include "io/file_bytes.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

#include "quadval/error.hpp"

namespace quadval::io {

namespace {

std::string read_stream(std::FILE* f, const std::string& name) {
  std::string bytes;
  char chunk[1 << 16];
  for (;;) {
    const std::size_t got = std::fread(chunk, 1, sizeof chunk, f);
    bytes.append(chunk, got);
    if (got < sizeof chunk) break;
  }
  if (std::ferror(f)) throw InputError::in_file(name, "read error");
  return bytes;
}

}  // namespace

FileBytes::FileBytes(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw InputError::in_file(name, "no such file");
  if (std::filesystem::is_directory(status))
    throw InputError::in_file(name, "is a directory, expected a mesh file");
  const int fd = ::open(name.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw InputError::in_file(name, std::string("cannot open for reading: ") + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
    void* p = ::mmap(nullptr, static_cast<std::size_t>(st.st_size), PROT_READ, MAP_PRIVATE, fd, 0);
    if (p != MAP_FAILED) {
      ::close(fd);
      map_ = p;
      map_size_ = static_cast<std::size_t>(st.st_size);
      ::madvise(map_, map_size_, MADV_SEQUENTIAL);
      view_ = std::string_view(static_cast<const char*>(map_), map_size_);
      return;
    }
  }
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(::fdopen(fd, "rb"), &std::fclose);
  if (!f) {
    ::close(fd);
    throw InputError::in_file(name, std::string("cannot open for reading: ") + std::strerror(errno));
  }
  copy_ = read_stream(f.get(), name);
  view_ = copy_;
}

FileBytes::~FileBytes() {
  if (map_ != nullptr) ::munmap(map_, map_size_);
}

void FileBytes::release_before(std::size_t offset) noexcept {
  if (map_ == nullptr) return;
  const auto page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  const std::size_t end = (offset < map_size_ ? offset : map_size_) / page * page;
  if (end <= released_) return;
  ::madvise(static_cast<char*>(map_) + released_, end - released_, MADV_DONTNEED);
  released_ = end;
}

}  // namespace quadval::io
