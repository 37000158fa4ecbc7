#include "examples/trainer/torch_common/conv_encoder.h"

#include <cmath>
#include <stdexcept>

namespace pixelgym::trainer {

const char* to_string(EncoderArchitecture architecture) {
  switch (architecture) {
    case EncoderArchitecture::kDrqV2:
      return "drqv2";
    case EncoderArchitecture::kMrq:
      return "mrq";
    case EncoderArchitecture::kFine:
      return "fine";
  }
  return "?";
}

std::vector<std::int64_t> encoder_strides(EncoderArchitecture architecture) {
  switch (architecture) {
    case EncoderArchitecture::kDrqV2:
      return {2, 1, 1, 1};
    case EncoderArchitecture::kMrq:
      return {2, 2, 2, 1};
    case EncoderArchitecture::kFine:
      return {2, 2, 1, 1};
  }
  return {};
}

EncoderArchitecture parse_encoder_architecture(const std::string& name) {
  if (name == "drqv2") return EncoderArchitecture::kDrqV2;
  if (name == "mrq") return EncoderArchitecture::kMrq;
  if (name == "fine") return EncoderArchitecture::kFine;
  throw std::invalid_argument("unknown encoder \"" + name + "\"; known: drqv2, mrq, fine");
}

void orthogonal_init(torch::nn::Module& module, double gain) {
  for (auto& child : module.modules(/*include_self=*/true)) {
    if (auto* linear = child->as<torch::nn::Linear>()) {
      torch::nn::init::orthogonal_(linear->weight, gain);
      torch::nn::init::zeros_(linear->bias);
    } else if (auto* conv = child->as<torch::nn::Conv2d>()) {
      torch::nn::init::orthogonal_(conv->weight, gain);
      torch::nn::init::zeros_(conv->bias);
    }
  }
}

ConvEncoder make_conv_encoder(EncoderArchitecture architecture, std::int64_t channels,
                              std::int64_t height, std::int64_t width, const std::string& who) {
  ConvEncoder encoder;
  encoder.layers = torch::nn::Sequential();
  std::int64_t h = height;
  std::int64_t w = width;
  for (const std::int64_t stride : encoder_strides(architecture)) {
    encoder.layers->push_back(
        torch::nn::Conv2d(torch::nn::Conv2dOptions(channels, 32, 3).stride(stride)));
    encoder.layers->push_back(torch::nn::ReLU());
    channels = 32;
    h = (h - 3) / stride + 1;
    w = (w - 3) / stride + 1;
    if (h < 1 || w < 1) {
      throw std::invalid_argument(who + ": images of " + std::to_string(height) + "x" +
                                  std::to_string(width) + " are too small for the " +
                                  to_string(architecture) + " encoder");
    }
  }
  encoder.layers->push_back(torch::nn::Flatten());
  orthogonal_init(*encoder.layers, std::sqrt(2.0));
  encoder.features = channels * h * w;
  return encoder;
}

}  // namespace pixelgym::trainer
