// libFuzzer target for the STL, OBJ and OFF readers; the first byte picks the reader.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "io/surface_read.hpp"
#include "quadval/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  std::vector<std::string> warnings;
  try {
    quadval::Mesh m;
    switch (data[0] % 3) {
      case 0: m = quadval::io::read_stl(bytes, "fuzz.stl", warnings); break;
      case 1: m = quadval::io::read_obj(bytes, "fuzz.obj", warnings); break;
      default: m = quadval::io::read_off(bytes, "fuzz.off", warnings); break;
    }
    for (const quadval::ElementBlock& b : m.blocks)
      for (quadval::NodeIndex v : b.nodes)
        if (v >= m.num_nodes()) __builtin_trap();
  } catch (const quadval::InputError&) {
  }
  return 0;
}
