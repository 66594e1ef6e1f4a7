#pragma once
// Whole-file input: every reader parses from memory, forward only.
#include <filesystem>
#include <string>
#include <string_view>

namespace quadval::io {

/// The bytes of a file. A regular file is mapped read-only (no copy); anything else (a
/// pipe, an empty file) is read into memory. Readers parse forward, so the pages of the
/// part already parsed can go back to the OS (release_before): a large mesh is then never
/// held in memory twice, once as text and once as a Mesh.
class FileBytes {
 public:
  /// Throws InputError naming the file when it does not exist, is a directory, or cannot
  /// be read.
  explicit FileBytes(const std::filesystem::path& path);
  ~FileBytes();
  FileBytes(const FileBytes&) = delete;
  FileBytes& operator=(const FileBytes&) = delete;

  std::string_view view() const noexcept { return view_; }

  /// Gives back the whole pages that lie before `offset`. Always safe: the mapping is
  /// private and never written, so touching those bytes again reads them from the file.
  /// A no-op for files read into memory.
  void release_before(std::size_t offset) noexcept;

 private:
  std::string copy_;           // the bytes, when not mapped
  void* map_ = nullptr;        // the mapping, when mapped
  std::size_t map_size_ = 0;
  std::size_t released_ = 0;   // bytes before this offset already given back
  std::string_view view_;
};

/// How far a reader may run before it gives parsed pages back (see FileBytes).
inline constexpr std::size_t kReleaseEvery = std::size_t{8} << 20;

}  // namespace quadval::io
