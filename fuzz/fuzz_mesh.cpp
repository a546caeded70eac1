// libFuzzer target: Gmsh .msh text -> validated closed membrane mesh, the path of `mesh.family = "file"`
// (read_gmsh: ASCII 2.2 and 4.1, 3- and 6-node triangles; then orient_outward and validate_closed_mesh).
// Accepted outcomes: a mesh, or an InputError whose message is one line.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/GmshReader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    immerse::read_gmsh(in, "fuzz.msh");
  } catch (const immerse::InputError& e) {
    if (std::strchr(e.what(), '\n')) {
      std::fprintf(stderr, "fuzz_mesh: multi-line message: %s\n", e.what());
      std::abort();
    }
  }
  return 0;
}
