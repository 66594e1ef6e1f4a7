#pragma once
/// Write-temp-then-rename, so that a failure never leaves a half-written output file
/// (DESIGN.md "Errors").

#include <filesystem>
#include <functional>
#include <ostream>

namespace quadval {

/// Calls `write` with a binary stream on a temporary file next to `path`, then renames it
/// to `path`. If `write` throws or the stream fails, the temporary file is removed, `path`
/// is left as it was, and the exception propagates (stream failures become InputError
/// naming `path`).
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write);

}  // namespace quadval
