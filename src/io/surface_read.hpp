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
/// other statements are ignored (unknown ones with a warning).
Mesh read_obj(std::string_view bytes, const std::string& file, std::vector<std::string>& warnings);
/// OFF: "OFF", counts "nv nf ne", nv vertex lines, nf face lines "k i_0 ... i_{k-1}" (0-based);
/// '#' starts a comment.
Mesh read_off(std::string_view bytes, const std::string& file, std::vector<std::string>& warnings);

}  // namespace quadval::io
