// Fuzz target: the URDF importer (engine::parse_urdf) on arbitrary file contents. Refusals are
// UrdfError (or the mesh importer's std::runtime_error) with a message; anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "fuzz/fuzz_input.h"
#include "pixelgym/engine/robot_model.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = pixelgym::fuzz::write_input_file(
      std::string(reinterpret_cast<const char*>(data), size), "robot.urdf");
  pixelgym::engine::MeshCache meshes;
  try {
    const auto model = pixelgym::engine::parse_urdf(path, meshes);
    if (model->links().empty()) std::abort();  // parse_urdf promises at least one link
  } catch (const std::runtime_error& error) {
    if (std::string(error.what()).empty()) std::abort();
  }
  return 0;
}
