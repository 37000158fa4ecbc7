// Fuzz target: DrQ-v2's config as `train --config` reads it (JSON, from_json, which validates),
// then what the accepted settings size without a run: the memory estimate, and the random shift
// (shift_frames) of a small batch of image stacks with the config's shift_pad (a pad wider than
// the image once wrote out of bounds). The first two bytes pick the image's height and width
// (1 to 16), the next eight the shifts; the rest is the JSON. A refusal is std::invalid_argument
// with a message; anything else is a finding.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "examples/trainer/drqv2/drqv2.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pixelgym;  // NOLINT(google-build-using-namespace): a fuzz target's body
  fuzz::FuzzInput input(data, size);
  const std::int64_t height = 1 + static_cast<std::int64_t>(input.pick(16));
  const std::int64_t width = 1 + static_cast<std::int64_t>(input.pick(16));
  const std::string shift_bytes = input.bytes(8);
  const nlohmann::json json = nlohmann::json::parse(input.rest(), nullptr, false);
  if (json.is_discarded()) return 0;
  drqv2::DrqV2Config config;
  try {
    drqv2::from_json(json, config);
  } catch (const std::invalid_argument& error) {
    if (std::string(error.what()).empty()) std::abort();
    return 0;
  }
  drqv2::InputLayout layout;
  layout.has_image = true;
  layout.stack = std::min<std::int64_t>(config.frame_stack, 4);
  layout.height = height;
  layout.width = width;
  layout.channels = 1;
  layout.action_size = 1;
  for (const trainer::MemoryUse& use : drqv2::memory_estimate(layout, config)) {
    if (!(use.bytes >= 0)) std::abort();
  }
  // Two stacks, each shifted by offsets in [0, 2 pad] from the input's bytes.
  const std::int64_t batch = 2;
  std::vector<std::uint8_t> images(static_cast<std::size_t>(batch * layout.stack * height * width));
  for (std::size_t i = 0; i < images.size(); ++i) images[i] = static_cast<std::uint8_t>(i);
  std::vector<std::uint8_t> shifted(images.size());
  std::vector<std::int64_t> shifts(4);
  for (std::size_t i = 0; i < shifts.size(); ++i) {
    const auto byte =
        i * 2 < shift_bytes.size() ? static_cast<std::uint8_t>(shift_bytes[i * 2]) : 0;
    shifts[i] = byte % (2 * config.shift_pad + 1);
  }
  drqv2::shift_frames(images.data(), shifted.data(), batch, layout.stack, height, width, 1,
                      config.shift_pad, shifts.data());
  return 0;
}
