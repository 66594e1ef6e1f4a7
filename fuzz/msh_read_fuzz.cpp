// libFuzzer target for the MSH readers (2.2 and 4.1, ASCII and binary): any input must
// either parse or raise InputError; sanitizers catch everything else.
//
//   CXX=clang++ cmake -S . -B build-fuzz -DQUADVAL_BUILD_FUZZ=ON
//   cmake --build build-fuzz --target msh_read_fuzz
//   build-fuzz/fuzz/msh_read_fuzz -max_total_time=60 fuzz/corpus_msh
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "io/msh_reader.hpp"
#include "quadval/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> warnings;
  try {
    const quadval::Mesh m =
        quadval::io::read_msh(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.msh", warnings);
    // A mesh that read must be consistent: every node index in range.
    for (const quadval::ElementBlock& b : m.blocks)
      for (quadval::NodeIndex v : b.nodes)
        if (v >= m.num_nodes()) __builtin_trap();
  } catch (const quadval::InputError&) {
  }
  return 0;
}
