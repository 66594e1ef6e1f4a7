#pragma once
// Triangle (and quadrangle) surface readers: STL, OBJ, OFF (conventions in io.hpp).
#include <string>
#include <string_view>
#include <vector>

#include "quadval/mesh.hpp"

namespace quadval::io {

/// STL, ASCII or binary (binary when the size is exactly 84 + 50 × the triangle count of
/// the header; ASCII when the text starts with "solid"). Vertices with identical
/// coordinates are merged (-0 and +0 are the same).
Mesh read_stl(std::string_view bytes, const std::string& file, std::vector<std::string>& warnings);
/// Wavefront OBJ: "v x y z [w]" and "f i[/t][/n] ..." lines (1-based or negative indices);
/// other statements are ignored (unknown ones with a warning). From 1 MiB on, in runs of
/// lines on OpenMP's threads (the mesh, warnings and errors are the same).
Mesh read_obj(std::string_view bytes, const std::string& file, std::vector<std::string>& warnings);
/// The same in `runs` runs of lines, one thread each (1: the whole file at once); where a run
/// finds an error, the whole file is read at once, which reports the file's first error.
/// @param runs_used  if not null: `runs`, or 1 where the whole file was read at once
Mesh read_obj(std::string_view bytes, const std::string& file, std::vector<std::string>& warnings,
              std::size_t runs, std::size_t* runs_used = nullptr);
/// OFF: "OFF", counts "nv nf ne", nv vertex lines, nf face lines "k i_0 ... i_{k-1}" (0-based);
/// '#' starts a comment.
Mesh read_off(std::string_view bytes, const std::string& file, std::vector<std::string>& warnings);

}  // namespace quadval::io
