// The convolutional encoders of the off-policy learners: four 3x3 convolutions of 32 channels
// (ReLU after each), flattened, with orthogonal weights, in three stride patterns.
#pragma once

#include <torch/torch.h>

#include <cstdint>
#include <string>
#include <vector>

namespace pixelgym::trainer {

/// The stride pattern of a conv encoder.
enum class EncoderArchitecture : std::uint8_t {
  /// DrQ-v2's: four convolutions of strides 2, 1, 1, 1 (at 64x64: 25x25 cells, 20000 features;
  /// about 23M multiply-adds per 9-channel sample).
  kDrqV2,
  /// MR.Q's (Fujimoto et al. 2025): strides 2, 2, 2, 1 (at 64x64: 5x5 cells, 800 features;
  /// about 5M multiply-adds per sample).
  kMrq,
  /// Between the two: strides 2, 2, 1, 1 (at 64x64: 11x11 cells, 3872 features; about 7M
  /// multiply-adds per sample), for thin things such as a pole a pixel or two wide.
  kFine,
};
/// "drqv2", "mrq", "fine".
const char* to_string(EncoderArchitecture architecture);
/// The strides of the architecture's four 3x3 convolutions.
std::vector<std::int64_t> encoder_strides(EncoderArchitecture architecture);
/// The inverse of to_string. Throws std::invalid_argument listing the names.
EncoderArchitecture parse_encoder_architecture(const std::string& name);

/// Orthogonal weights of gain `gain` and zero biases for every Linear and Conv2d in `module`
/// (itself included), in module order; draws from torch's default generator.
void orthogonal_init(torch::nn::Module& module, double gain);

/// A conv encoder and the width of its flattened output.
struct ConvEncoder {
  torch::nn::Sequential layers{nullptr};
  std::int64_t features = 0;
};

/// The encoder of `architecture` over float (B, channels, height, width) images: each
/// Conv2d(in, 32, 3, stride) then ReLU, a Flatten, orthogonal weights of gain sqrt(2) (drawn
/// from torch's default generator after the layers are built). Throws std::invalid_argument,
/// naming `who`, the image size and the architecture, when the images are too small for it.
ConvEncoder make_conv_encoder(EncoderArchitecture architecture, std::int64_t channels,
                              std::int64_t height, std::int64_t width, const std::string& who);

}  // namespace pixelgym::trainer
