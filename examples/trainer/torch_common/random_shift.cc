#include "examples/trainer/torch_common/random_shift.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

namespace pixelgym::trainer {

torch::Tensor random_shift(const torch::Tensor& images, const torch::Tensor& shifts,
                           std::int64_t pad) {
  const std::int64_t b = images.size(0);
  if (shifts.scalar_type() != torch::kInt64 || shifts.dim() != 2 || shifts.size(0) != b ||
      shifts.size(1) != 2) {
    throw std::invalid_argument("random_shift: shifts must be int64 (" + std::to_string(b) +
                                ", 2), got " + c10::str(shifts.sizes()));
  }
  if (pad < 0 || (shifts.numel() > 0 && (shifts.min().item<std::int64_t>() < 0 ||
                                         shifts.max().item<std::int64_t>() > 2 * pad))) {
    throw std::invalid_argument("random_shift: offsets must lie in [0, " + std::to_string(2 * pad) +
                                "]");
  }
  const std::int64_t c = images.size(1);
  const std::int64_t h = images.size(2);
  const std::int64_t w = images.size(3);
  // Row r of the output reads padded row r + dy, i.e. source row clamp(r + dy - pad): the same
  // as replicate padding then cropping, without building the padded image.
  const torch::Tensor rows =
      (torch::arange(h, torch::kInt64).unsqueeze(0) + shifts.select(1, 0).unsqueeze(1) - pad)
          .clamp(0, h - 1);
  const torch::Tensor cols =
      (torch::arange(w, torch::kInt64).unsqueeze(0) + shifts.select(1, 1).unsqueeze(1) - pad)
          .clamp(0, w - 1);
  const torch::Tensor by_rows = images.gather(2, rows.view({b, 1, h, 1}).expand({b, c, h, w}));
  return by_rows.gather(3, cols.view({b, 1, 1, w}).expand({b, c, h, w}));
}

void shift_frames(const std::uint8_t* images, std::uint8_t* shifted, std::int64_t batch,
                  std::int64_t frames, std::int64_t height, std::int64_t width,
                  std::int64_t channels, std::int64_t pad, const std::int64_t* shifts) {
  const std::int64_t row_bytes = width * channels;
  const std::int64_t frame_bytes = height * row_bytes;
  for (std::int64_t b = 0; b < batch; ++b) {
    const std::int64_t dy = shifts[2 * b] - pad;
    const std::int64_t dx = shifts[2 * b + 1] - pad;
    // Output column x reads source column clamp(x + dx): the columns in range are one copy,
    // the ones past an edge repeat the edge pixel. A shift as wide as the image (pad >= width)
    // leaves no column in range: first == last, and every column repeats an edge.
    const std::int64_t first = std::clamp<std::int64_t>(-dx, 0, width);  // first x in range
    const std::int64_t last = std::clamp<std::int64_t>(width - dx, first, width);  // one past it
    for (std::int64_t f = 0; f < frames; ++f) {
      const std::uint8_t* source = images + (b * frames + f) * frame_bytes;
      std::uint8_t* dest = shifted + (b * frames + f) * frame_bytes;
      for (std::int64_t y = 0; y < height; ++y) {
        const std::int64_t sy = std::clamp<std::int64_t>(y + dy, 0, height - 1);
        const std::uint8_t* in = source + sy * row_bytes;
        std::uint8_t* out = dest + y * row_bytes;
        for (std::int64_t x = 0; x < first; ++x) {
          std::memcpy(out + x * channels, in, static_cast<std::size_t>(channels));
        }
        if (last > first) {
          std::memcpy(out + first * channels, in + (first + dx) * channels,
                      static_cast<std::size_t>((last - first) * channels));
        }
        for (std::int64_t x = last; x < width; ++x) {
          std::memcpy(out + x * channels, in + (width - 1) * channels,
                      static_cast<std::size_t>(channels));
        }
      }
    }
  }
}

}  // namespace pixelgym::trainer
