// Fuzz target: the golden-PNG reader (render::read_png, through which compare_to_golden reads
// goldens) on arbitrary file contents. A refusal is std::runtime_error with a message; an image it
// accepts has the size it says.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "fuzz/fuzz_input.h"
#include "pixelgym/render/image_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = pixelgym::fuzz::write_input_file(
      std::string(reinterpret_cast<const char*>(data), size), "golden.png");
  try {
    const pixelgym::render::Image image = pixelgym::render::read_png(path);
    const auto expected = static_cast<std::size_t>(image.width) *
                          static_cast<std::size_t>(image.height) *
                          static_cast<std::size_t>(image.channels);
    if (image.width <= 0 || image.height <= 0 || image.pixels.size() != expected) std::abort();
  } catch (const std::runtime_error& error) {
    if (std::string(error.what()).empty()) std::abort();
  }
  return 0;
}
