// The public entry points of io.hpp: choose the format, read, write atomically.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <stdexcept>

#include <fmt/core.h>

#include "io/file_bytes.hpp"
#include "io/msh_reader.hpp"
#include "io/msh_write.hpp"
#include "io/surface_read.hpp"
#include "io/surface_write.hpp"
#include "io/vtu_write.hpp"
#include "quadval/atomic_file.hpp"
#include "quadval/error.hpp"
#include "quadval/io.hpp"

namespace quadval {

namespace {
constexpr const char* kStlReadOnly = "STL is read only (it holds triangles only); write .msh, .vtu, .obj or .off";
}  // namespace

MeshFormat format_from_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".msh") return MeshFormat::msh41;
  if (ext == ".vtu") return MeshFormat::vtu;
  if (ext == ".stl") return MeshFormat::stl;
  if (ext == ".obj") return MeshFormat::obj;
  if (ext == ".off") return MeshFormat::off;
  throw InputError::in_file(path.string(),
                            fmt::format("unknown extension '{}', expected .msh, .vtu, .stl, .obj or .off", ext));
}

MeshFormat output_format_from_extension(const std::filesystem::path& path) {
  const MeshFormat format = format_from_extension(path);
  if (format == MeshFormat::stl)
    throw InputError::in_file(path.string(), kStlReadOnly);
  return format;
}

Mesh read_mesh(const std::filesystem::path& path, std::vector<std::string>* warnings) {
  const std::string name = path.string();
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError::in_file(name, "is a directory, expected a mesh file");
  const MeshFormat format = format_from_extension(path);
  if (format == MeshFormat::vtu)
    throw InputError::in_file(name, "reading VTU is not supported, expected .msh, .stl, .obj or .off");
  io::FileBytes file(path);
  const std::string_view bytes = file.view();
  std::vector<std::string> local;
  std::vector<std::string>& out = warnings ? *warnings : local;
  Mesh mesh;
  switch (format) {
    case MeshFormat::stl: mesh = io::read_stl(bytes, name, out); break;
    case MeshFormat::obj: mesh = io::read_obj(bytes, name, out); break;
    case MeshFormat::off: mesh = io::read_off(bytes, name, out); break;
    default: mesh = io::read_msh(bytes, name, out, &file); break;
  }
  if (!warnings)
    for (const std::string& w : local) fmt::print(stderr, "quadval: warning: {}\n", w);
  return mesh;
}

void write_mesh(const Mesh& mesh, const std::filesystem::path& path, const WriteOptions& options,
                std::span<const ElementField> fields) {
  const std::string name = path.string();
  for (const ElementField& f : fields)
    if (f.values.size() != mesh.num_elements())
      throw std::invalid_argument(fmt::format("field '{}' has {} values for {} elements", f.name,
                                              f.values.size(), mesh.num_elements()));
  switch (options.format) {
    case MeshFormat::msh22:
    case MeshFormat::msh41:
      write_file_atomically(path, [&](std::ostream& out) {
        io::write_msh(mesh, out, options.format == MeshFormat::msh41, options.binary, fields, name);
      });
      return;
    case MeshFormat::vtu:
      write_file_atomically(path, [&](std::ostream& out) { io::write_vtu(mesh, out, fields, name); });
      return;
    case MeshFormat::obj:
      write_file_atomically(path, [&](std::ostream& out) { io::write_obj(mesh, out, name); });
      return;
    case MeshFormat::off:
      write_file_atomically(path, [&](std::ostream& out) { io::write_off(mesh, out, name); });
      return;
    case MeshFormat::stl:
      break;
  }
  throw InputError::in_file(name, kStlReadOnly);
}

}  // namespace quadval
