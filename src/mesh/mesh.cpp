#include "quadval/mesh.hpp"

#include <algorithm>

namespace quadval {

std::size_t Mesh::num_elements() const noexcept {
  std::size_t n = 0;
  for (const ElementBlock& b : blocks) n += b.size();
  return n;
}

int Mesh::dimension() const noexcept {
  int d = -1;
  for (const ElementBlock& b : blocks) d = std::max(d, b.type->dim);
  return d;
}

}  // namespace quadval
