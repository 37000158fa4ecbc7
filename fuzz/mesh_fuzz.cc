// Fuzz target: the mesh importer (engine::load_mesh, our code around assimp) on arbitrary file
// contents. The first byte picks the file's extension (.obj, .stl, .dae, .ply); the rest is the
// file. A refusal is std::runtime_error with a message; a mesh it accepts must be well formed.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "fuzz/fuzz_input.h"
#include "pixelgym/engine/mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pixelgym::fuzz::FuzzInput input(data, size);
  static const char* const kExtensions[] = {"obj", "stl", "dae", "ply"};
  const std::string name = std::string("mesh.") + kExtensions[input.pick(4)];
  const std::string path = pixelgym::fuzz::write_input_file(input.rest(), name);
  try {
    const auto mesh = pixelgym::engine::load_mesh(path);
    // What every user of a Mesh relies on.
    if (mesh->indices.empty() || mesh->indices.size() % 3 != 0) std::abort();
    if (mesh->normals.size() != mesh->positions.size()) std::abort();
    for (const std::uint32_t index : mesh->indices) {
      if (index >= mesh->positions.size()) std::abort();
    }
    std::size_t covered = 0;
    for (const auto& part : mesh->parts) {
      if (part.index_count % 3 != 0 || part.first_index + part.index_count > mesh->indices.size())
        std::abort();
      covered += part.index_count;
    }
    if (covered != mesh->indices.size()) std::abort();
  } catch (const std::runtime_error& error) {
    if (std::string(error.what()).empty()) std::abort();
  }
  return 0;
}
