// MSH 4.1 and 2.2 writers, ASCII and binary (conventions in io.hpp). Doubles are printed
// with fmt's shortest representation that reads back to the same value.
#include "io/msh_write.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>

#include "io/out_buffer.hpp"
#include "quadval/error.hpp"

namespace quadval::io {

namespace {

void check_mesh(const Mesh& mesh) {
  QV_ASSERT(mesh.coords.size() == 3 * mesh.node_tags.size(),
            mesh.coords.size() << " coordinates for " << mesh.node_tags.size() << " nodes");
  const std::size_t n = mesh.num_nodes();
  for (const ElementBlock& b : mesh.blocks) {
    QV_ASSERT(b.type != nullptr && b.type->num_nodes > 0, "block without a fixed-size type");
    QV_ASSERT(b.nodes.size() == b.tags.size() * static_cast<std::size_t>(b.type->num_nodes),
              "block of " << b.type->name << ": " << b.nodes.size() << " node indices for "
                          << b.tags.size() << " elements");
    for (NodeIndex v : b.nodes) QV_ASSERT(v < n, "node index " << v << " >= " << n);
  }
}

std::pair<Tag, Tag> tag_range(const std::vector<Tag>& tags) {
  if (tags.empty()) return {0, 0};
  auto [lo, hi] = std::minmax_element(tags.begin(), tags.end());
  return {*lo, *hi};
}

class MshWriter {
 public:
  MshWriter(const Mesh& mesh, std::ostream& out, bool binary, const std::string& file)
      : mesh_(mesh), out_(out), binary_(binary), file_(file) {}

  void header(bool version41) {
    out_.text("$MeshFormat\n{} {} 8\n", version41 ? "4.1" : "2.2", binary_ ? 1 : 0);
    if (binary_) {
      out_.raw(std::int32_t{1});
      out_.text("\n");
    }
    out_.text("$EndMeshFormat\n");
  }

  void physical_names() {
    if (mesh_.physical_names.empty()) return;
    out_.text("$PhysicalNames\n{}\n", mesh_.physical_names.size());
    for (const PhysicalGroup& g : mesh_.physical_names) {
      std::string name = g.name;
      std::replace(name.begin(), name.end(), '\n', ' ');
      out_.text("{} {} \"{}\"\n", g.dim, g.tag, name);
    }
    out_.text("$EndPhysicalNames\n");
  }

  void entities41() {
    if (mesh_.entities.empty()) return;
    std::uint64_t counts[4] = {0, 0, 0, 0};
    for (const Entity& e : mesh_.entities) {
      QV_ASSERT(e.dim >= 0 && e.dim <= 3, "entity dimension " << e.dim);
      ++counts[e.dim];
    }
    out_.text("$Entities\n");
    if (binary_) {
      for (std::uint64_t c : counts) out_.raw(c);
    } else {
      out_.text("{} {} {} {}\n", counts[0], counts[1], counts[2], counts[3]);
    }
    for (int d = 0; d < 4; ++d) {
      for (const Entity& e : mesh_.entities) {
        if (e.dim != d) continue;
        const int num_coords = d == 0 ? 3 : 6;
        if (binary_) {
          out_.raw(std::int32_t{e.tag});
          for (int k = 0; k < num_coords; ++k) out_.raw(e.box[k]);
          out_.raw(std::uint64_t{e.physical_tags.size()});
          for (int t : e.physical_tags) out_.raw(std::int32_t{t});
          if (d > 0) {
            out_.raw(std::uint64_t{e.boundary_tags.size()});
            for (int t : e.boundary_tags) out_.raw(std::int32_t{t});
          }
        } else {
          out_.text("{}", e.tag);
          for (int k = 0; k < num_coords; ++k) out_.text(" {}", e.box[k]);
          out_.text(" {}", e.physical_tags.size());
          for (int t : e.physical_tags) out_.text(" {}", t);
          if (d > 0) {
            out_.text(" {}", e.boundary_tags.size());
            for (int t : e.boundary_tags) out_.text(" {}", t);
          }
          out_.text("\n");
        }
      }
    }
    end_section("Entities");
  }

  void nodes41() {
    const std::vector<NodeBlock> blocks = node_blocks41();
    const auto [lo, hi] = tag_range(mesh_.node_tags);
    out_.text("$Nodes\n");
    if (binary_) {
      for (std::uint64_t v : {std::uint64_t{blocks.size()}, std::uint64_t{mesh_.num_nodes()}, lo, hi}) out_.raw(v);
    } else {
      out_.text("{} {} {} {}\n", blocks.size(), mesh_.num_nodes(), lo, hi);
    }
    for (const NodeBlock& b : blocks) {
      if (binary_) {
        out_.raw(std::int32_t{b.entity_dim});
        out_.raw(std::int32_t{b.entity_tag});
        out_.raw(std::int32_t{0});
        out_.raw(std::uint64_t{b.count});
        static_assert(sizeof(Tag) == 8);
        out_.bytes(mesh_.node_tags.data() + b.first, b.count * sizeof(Tag));
        out_.bytes(mesh_.coords.data() + 3 * b.first, 3 * b.count * sizeof(double));
      } else {
        out_.text("{} {} 0 {}\n", b.entity_dim, b.entity_tag, b.count);
        out_.records(b.count, [&](OutBuffer& o, std::size_t i) {
          o.integer(mesh_.node_tags[b.first + i]);
          o.put('\n');
        });
        out_.records(b.count, [&](OutBuffer& o, std::size_t i) { coordinates(o, b.first + i); });
      }
    }
    end_section("Nodes");
  }

  void elements41() {
    Tag lo = std::numeric_limits<Tag>::max(), hi = 0;
    for (const ElementBlock& b : mesh_.blocks) {
      const auto [l, h] = tag_range(b.tags);
      if (!b.tags.empty()) lo = std::min(lo, l), hi = std::max(hi, h);
    }
    if (hi == 0) lo = 0;
    out_.text("$Elements\n");
    if (binary_) {
      for (std::uint64_t v : {std::uint64_t{mesh_.blocks.size()}, std::uint64_t{mesh_.num_elements()}, lo, hi})
        out_.raw(v);
    } else {
      out_.text("{} {} {} {}\n", mesh_.blocks.size(), mesh_.num_elements(), lo, hi);
    }
    std::vector<std::uint64_t> record;
    for (const ElementBlock& b : mesh_.blocks) {
      if (binary_) {
        out_.raw(std::int32_t{b.entity_dim});
        out_.raw(std::int32_t{b.entity_tag});
        out_.raw(std::int32_t{b.type->gmsh_id});
        out_.raw(std::uint64_t{b.size()});
      } else {
        out_.text("{} {} {} {}\n", b.entity_dim, b.entity_tag, b.type->gmsh_id, b.size());
      }
      if (!binary_) {
        out_.records(b.size(), [&](OutBuffer& o, std::size_t e) {
          o.integer(b.tags[e]);
          node_tags(o, b.element(e));
        });
        continue;
      }
      for (std::size_t e = 0; e < b.size(); ++e) {
        record.clear();
        record.push_back(b.tags[e]);
        for (NodeIndex v : b.element(e)) record.push_back(mesh_.node_tags[v]);
        out_.bytes_buffered(record.data(), record.size() * sizeof(std::uint64_t));
      }
    }
    end_section("Elements");
  }

  void nodes22() {
    out_.text("$Nodes\n{}\n", mesh_.num_nodes());
    if (binary_) {
      for (std::size_t i = 0; i < mesh_.num_nodes(); ++i) {
        out_.raw(int_tag(mesh_.node_tags[i], "node"));
        out_.bytes_buffered(mesh_.coords.data() + 3 * i, 3 * sizeof(double));
      }
    } else {
      out_.records(mesh_.num_nodes(), [&](OutBuffer& o, std::size_t i) {
        o.integer(int_tag(mesh_.node_tags[i], "node"));
        o.put(' ');
        coordinates(o, i);
      });
    }
    end_section("Nodes");
  }

  void elements22() {
    // Physical tags of each block's entity (once with 0 when it has none).
    std::vector<std::vector<int>> physicals(mesh_.blocks.size());
    std::size_t total = 0;
    Tag next_tag = 1;
    for (std::size_t b = 0; b < mesh_.blocks.size(); ++b) {
      const ElementBlock& block = mesh_.blocks[b];
      for (const Entity& e : mesh_.entities)
        if (e.dim == block.entity_dim && e.tag == block.entity_tag) physicals[b] = e.physical_tags;
      if (physicals[b].empty()) physicals[b].push_back(0);
      total += block.size() * physicals[b].size();
      for (Tag t : block.tags) next_tag = std::max(next_tag, t + 1);
    }
    out_.text("$Elements\n{}\n", total);
    std::vector<std::int32_t> record;
    for (std::size_t b = 0; b < mesh_.blocks.size(); ++b) {
      const ElementBlock& block = mesh_.blocks[b];
      if (block.size() == 0) continue;
      const std::int32_t elementary = block.entity_tag;
      for (std::size_t p = 0; p < physicals[b].size(); ++p) {
        const std::int32_t physical = physicals[b][p];
        if (binary_) {
          out_.raw(std::int32_t{block.type->gmsh_id});
          out_.raw(int_count(block.size()));
          out_.raw(std::int32_t{2});
        }
        // The first group keeps the element's tags; copies for further groups get fresh ones.
        const Tag fresh = next_tag;
        const auto tag_of = [&](std::size_t e) {
          return int_tag(p == 0 ? block.tags[e] : fresh + e, "element");
        };
        if (p > 0) next_tag += block.size();
        if (!binary_) {
          out_.records(block.size(), [&](OutBuffer& o, std::size_t e) {
            o.text("{} {} 2 {} {}", tag_of(e), block.type->gmsh_id, physical, elementary);
            node_tags(o, block.element(e));
          });
          continue;
        }
        for (std::size_t e = 0; e < block.size(); ++e) {
          record.assign({tag_of(e), physical, elementary});
          for (NodeIndex v : block.element(e)) record.push_back(int_tag(mesh_.node_tags[v], "node"));
          out_.bytes_buffered(record.data(), record.size() * sizeof(std::int32_t));
        }
      }
    }
    end_section("Elements");
  }

  void element_data(const ElementField& field) {
    if (field.values.size() != mesh_.num_elements())
      throw std::invalid_argument("field '" + field.name + "' has " + std::to_string(field.values.size()) +
                                  " values for " + std::to_string(mesh_.num_elements()) + " elements");
    out_.text("$ElementData\n1\n\"{}\"\n1\n0\n3\n0\n1\n{}\n", field.name, field.values.size());
    std::size_t first = 0;  // the block's first value
    for (const ElementBlock& b : mesh_.blocks) {
      if (binary_) {
        for (std::size_t e = 0; e < b.size(); ++e) {
          out_.raw(int_tag(b.tags[e], "element"));
          out_.raw(field.values[first + e]);
        }
      } else {
        out_.records(b.size(), [&](OutBuffer& o, std::size_t e) {
          o.integer(b.tags[e]);
          o.put(' ');
          o.real(field.values[first + e]);
          o.put('\n');
        });
      }
      first += b.size();
    }
    end_section("ElementData");
  }

  void finish() { out_.flush(); }

  // " tag tag ... tag\n" of the element's nodes.
  void node_tags(OutBuffer& o, std::span<const NodeIndex> element) const {
    for (NodeIndex v : element) {
      o.put(' ');
      o.integer(mesh_.node_tags[v]);
    }
    o.put('\n');
  }
  // "x y z\n" of node i.
  void coordinates(OutBuffer& o, std::size_t i) const {
    o.real(mesh_.coords[3 * i]);
    o.put(' ');
    o.real(mesh_.coords[3 * i + 1]);
    o.put(' ');
    o.real(mesh_.coords[3 * i + 2]);
    o.put('\n');
  }

 private:
  void end_section(std::string_view name) { out_.text("{}$End{}\n", binary_ ? "\n" : "", name); }

  std::int32_t int_tag(Tag tag, std::string_view what) const {
    if (tag > static_cast<Tag>(std::numeric_limits<std::int32_t>::max()))
      throw InputError::in_file(file_, fmt::format("{} tag {} does not fit the int of this format; write MSH 4.1 (ASCII)", what, tag));
    return static_cast<std::int32_t>(tag);
  }
  std::int32_t int_count(std::size_t n) const {
    if (n > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
      throw InputError::in_file(file_, fmt::format("{} elements in one block do not fit MSH 2.2 binary", n));
    return static_cast<std::int32_t>(n);
  }

  /// The mesh's node blocks, or one derived block on the entity of the first element block
  /// of the highest dimension (Gmsh needs every node on an entity).
  std::vector<NodeBlock> node_blocks41() const {
    const std::size_t n = mesh_.num_nodes();
    if (!mesh_.node_blocks.empty()) {
      std::size_t next = 0;
      for (const NodeBlock& b : mesh_.node_blocks) {
        QV_ASSERT(b.first == next, "node block starts at " << b.first << ", expected " << next);
        next += b.count;
      }
      QV_ASSERT(next == n, "node blocks cover " << next << " of " << n << " nodes");
      return mesh_.node_blocks;
    }
    if (n == 0) return {};
    NodeBlock all;
    all.count = n;
    int best_dim = -1;
    for (const ElementBlock& b : mesh_.blocks) {
      if (b.type->dim > best_dim) {
        best_dim = b.type->dim;
        all.entity_dim = b.entity_dim;
        all.entity_tag = b.entity_tag;
      }
    }
    return {all};
  }

  const Mesh& mesh_;
  OutBuffer out_;
  bool binary_;
  const std::string& file_;
};

}  // namespace

void write_msh(const Mesh& mesh, std::ostream& out, bool version41, bool binary,
               std::span<const ElementField> fields, const std::string& file) {
  check_mesh(mesh);
  MshWriter w(mesh, out, binary, file);
  w.header(version41);
  w.physical_names();
  if (version41) {
    w.entities41();
    w.nodes41();
    w.elements41();
  } else {
    w.nodes22();
    w.elements22();
  }
  for (const ElementField& f : fields) w.element_data(f);
  w.finish();
}

}  // namespace quadval::io
