#pragma once
// Whole-file input: every reader parses from memory.
#include <filesystem>
#include <string>

namespace quadval::io {

/// The bytes of the file at `path`. Throws InputError naming the file when it does not
/// exist, is a directory, or cannot be read.
std::string read_file_bytes(const std::filesystem::path& path);

}  // namespace quadval::io
