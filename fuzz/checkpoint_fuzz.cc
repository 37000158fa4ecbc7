// Fuzz target: the checkpoint reader (trainer::read_checkpoint, all or nothing) on arbitrary file
// contents, and unpack_blobs (the bytes ranks send each other) on the same bytes. A refusal is
// std::runtime_error with a message; what is accepted writes back to the same bytes.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "fuzz/fuzz_input.h"
#include "pixelgym/trainer/checkpoint_file.h"

namespace {

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  const std::string path = pixelgym::fuzz::write_input_file(bytes, "ckpt-000001.pgck");
  try {
    const pixelgym::trainer::CheckpointBlobs blobs = pixelgym::trainer::read_checkpoint(path);
    // Whole and intact: written again, it is the same file.
    const std::string again = pixelgym::fuzz::write_input_file("", "again.pgck");
    pixelgym::trainer::write_checkpoint(again, blobs);
    if (read_all(again) != bytes) std::abort();
  } catch (const std::runtime_error& error) {
    if (std::string(error.what()).empty()) std::abort();
  }
  try {
    const pixelgym::trainer::CheckpointBlobs blobs =
        pixelgym::trainer::unpack_blobs(bytes, "fuzz input");
    if (pixelgym::trainer::pack_blobs(blobs) != bytes) std::abort();
  } catch (const std::runtime_error& error) {
    if (std::string(error.what()).empty()) std::abort();
  }
  return 0;
}
