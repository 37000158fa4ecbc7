// DrQ's random shift (Kostrikov et al. 2020): pad by repeating the edge pixels, then crop at a
// random offset. Two forms of the one operation: on a float (B, C, H, W) tensor (PPO's augment),
// and on uint8 frame stacks as a replay buffer stores them (DrQ-v2's, before the float copy).
#pragma once

#include <torch/torch.h>

#include <cstdint>

namespace pixelgym::trainer {

/// The shift on a float (B, C, H, W) batch: image b is padded by `pad` pixels on each side by
/// repeating its edge pixels, then the (H, W) window at offset (shifts[b][0], shifts[b][1])
/// (rows, columns; each in [0, 2 pad]) is kept. Offset (pad, pad) gives the image back
/// unchanged. Throws std::invalid_argument when `shifts` is not int64 (B, 2) or an offset is out
/// of range.
torch::Tensor random_shift(const torch::Tensor& images, const torch::Tensor& shifts,
                           std::int64_t pad);

/// The shift on uint8 stacks: `batch` stacks of `frames` frames of (height, width, channels)
/// bytes at `images`, written to `shifted` (the same size); frame f of stack b is padded by
/// `pad` pixels on each side, repeating its edge pixels, and the window at offset (shifts[2b],
/// shifts[2b + 1]) (rows, columns; each in [0, 2 pad], not checked) is kept: the same offset for
/// every frame of a stack. Offset (pad, pad) copies the stack unchanged; a pad as wide as the
/// image repeats an edge pixel in every column.
void shift_frames(const std::uint8_t* images, std::uint8_t* shifted, std::int64_t batch,
                  std::int64_t frames, std::int64_t height, std::int64_t width,
                  std::int64_t channels, std::int64_t pad, const std::int64_t* shifts);

}  // namespace pixelgym::trainer
