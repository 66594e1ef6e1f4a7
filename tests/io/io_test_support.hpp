#pragma once
// Shared by the io tests: a scratch directory, random meshes of any element type, and
// reading files as bytes.
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "quadval/error.hpp"
#include "quadval/io.hpp"
#include "quadval/mesh.hpp"

namespace quadval::testing_io {

/// A fresh directory under the system temp dir, removed when the object dies.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& name)
      : path_(std::filesystem::temp_directory_path() /
              ("quadval_io_" + name + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  std::filesystem::path operator/(const std::string& file) const { return path_ / file; }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline std::string file_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void write_bytes(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

/// Writes `text` to `path`, then reads it as a mesh.
inline Mesh read_mesh_text(const std::filesystem::path& path, const std::string& text,
                           std::vector<std::string>* warnings = nullptr) {
  write_bytes(path, text);
  return read_mesh(path, warnings);
}

/// The message of the InputError that reading `text` (written to `path`) raises; "" if none.
inline std::string read_mesh_error(const std::filesystem::path& path, const std::string& text) {
  try {
    read_mesh_text(path, text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// Doubles that printing must not round: fractions, huge and tiny magnitudes, subnormals.
inline double awkward_double(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  switch (rng() % 8) {
    case 0: return unit(rng) * 1e300;
    case 1: return unit(rng) * 1e-300;
    case 2: return 4.9406564584124654e-324 * static_cast<double>(rng() % 1000);  // subnormal
    case 3: return static_cast<double>(static_cast<std::int64_t>(rng() % 2001) - 1000);
    case 4: return 0.1 * static_cast<double>(rng() % 10);
    default: return unit(rng) * 1000.0;
  }
}

/// How the random mesh should look.
enum class Layout {
  msh41,  ///< node blocks, entities with boxes and boundaries (what a 4.1 read gives)
  msh22,  ///< no node blocks; entities as a 2.2 read makes them (io.hpp)
};

/// A mesh with one block per type (each on its own entity), random connectivity, node tags
/// shuffled with gaps, element tags unique with gaps, awkward coordinates. The first
/// block's entity is in two physical groups, the second's in one.
inline Mesh random_mesh(const std::vector<const ElementType*>& types, std::uint64_t seed, Layout layout,
                        std::size_t elements_per_block = 3) {
  std::mt19937_64 rng(seed);
  Mesh m;
  const std::size_t n = 20 + rng() % 30;
  std::vector<Tag> tags(n);
  Tag t = 0;
  for (Tag& x : tags) x = (t += 1 + rng() % 5);
  std::shuffle(tags.begin(), tags.end(), rng);
  m.node_tags = tags;
  for (std::size_t i = 0; i < 3 * n; ++i) m.coords.push_back(awkward_double(rng));
  Tag element_tag = 0;
  int entity_tag = 0;
  for (std::size_t b = 0; b < types.size(); ++b) {
    ElementBlock block;
    block.type = types[b];
    block.entity_dim = types[b]->dim;
    block.entity_tag = ++entity_tag + static_cast<int>(rng() % 3);
    entity_tag = block.entity_tag;
    for (std::size_t e = 0; e < elements_per_block; ++e) {
      block.tags.push_back(element_tag += 1 + rng() % 4);
      for (int k = 0; k < types[b]->num_nodes; ++k) block.nodes.push_back(static_cast<NodeIndex>(rng() % n));
    }
    Entity entity;
    entity.dim = block.entity_dim;
    entity.tag = block.entity_tag;
    if (b == 0) entity.physical_tags = {7, 3};
    if (b == 1) entity.physical_tags = {11};
    if (layout == Layout::msh41) {
      for (double& c : entity.box) c = awkward_double(rng);
      if (entity.dim == 0) std::copy(entity.box.begin(), entity.box.begin() + 3, entity.box.begin() + 3);
      if (entity.dim > 0) entity.boundary_tags = {1, -2};
    }
    m.blocks.push_back(std::move(block));
    m.entities.push_back(std::move(entity));
  }
  if (layout == Layout::msh41) {
    // Entities sorted by dimension, as $Entities lists them, plus an unused point.
    Entity point;
    point.dim = 0;
    point.tag = 999;
    point.box = {1.5, -2.25, 3, 1.5, -2.25, 3};
    m.entities.push_back(point);
    std::stable_sort(m.entities.begin(), m.entities.end(),
                     [](const Entity& a, const Entity& b) { return a.dim < b.dim; });
    const std::size_t split = n / 3;
    m.node_blocks.push_back({0, 999, 0, split});
    m.node_blocks.push_back({m.blocks.empty() ? 0 : m.blocks[0].entity_dim,
                             m.blocks.empty() ? 0 : m.blocks[0].entity_tag, split, n - split});
  }
  m.physical_names = {{2, 7, "a surface"}, {1, 3, "wall \"left\""}, {3, 11, ""}};
  return m;
}

/// All registry types with a fixed node count.
inline std::vector<const ElementType*> fixed_size_types() {
  std::vector<const ElementType*> out;
  for (const ElementType& t : element_types())
    if (t.num_nodes > 0) out.push_back(&t);
  return out;
}

}  // namespace quadval::testing_io
