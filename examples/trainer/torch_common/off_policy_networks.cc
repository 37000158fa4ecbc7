#include "examples/trainer/torch_common/off_policy_networks.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace pixelgym::trainer {

torch::nn::Sequential make_feature_head(std::int64_t in, std::int64_t features) {
  torch::nn::Sequential head(torch::nn::Linear(in, features),
                             torch::nn::LayerNorm(torch::nn::LayerNormOptions({features})),
                             torch::nn::Tanh());
  orthogonal_init(*head, 1.0);
  return head;
}

torch::nn::Sequential make_relu_mlp(std::int64_t in, std::int64_t hidden, std::int64_t depth,
                                    std::int64_t out) {
  torch::nn::Sequential mlp;
  std::int64_t width = in;
  for (std::int64_t layer = 0; layer < depth; ++layer) {
    mlp->push_back(torch::nn::Linear(width, hidden));
    mlp->push_back(torch::nn::ReLU());
    width = hidden;
  }
  mlp->push_back(torch::nn::Linear(width, out));
  orthogonal_init(*mlp, std::sqrt(2.0));
  return mlp;
}

void step_on_loss(const torch::Tensor& loss, double value, const std::string& what,
                  const std::vector<torch::optim::Optimizer*>& optimizers,
                  const std::string& detail) {
  if (!std::isfinite(value)) {
    throw std::runtime_error(what + " is not finite (" + std::to_string(value) + detail +
                             "): no step taken");
  }
  for (auto* optimizer : optimizers) optimizer->zero_grad();
  loss.backward();
  for (auto* optimizer : optimizers) optimizer->step();
}

CpuAutocast::CpuAutocast(bool on) : on_(on) {
  if (!on_) return;
  previous_ = at::autocast::is_cpu_enabled();
  at::autocast::set_cpu_enabled(true);
  at::autocast::set_autocast_cpu_dtype(at::kBFloat16);
  at::autocast::increment_nesting();
}

CpuAutocast::~CpuAutocast() {
  if (!on_) return;
  if (at::autocast::decrement_nesting() == 0) at::autocast::clear_cache();
  at::autocast::set_cpu_enabled(previous_);
}

bool cpu_has_bfloat16() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpuinfo, line)) {
    if (line.rfind("flags", 0) != 0) continue;
    std::istringstream flags(line);
    std::string flag;
    while (flags >> flag) {
      if (flag == "avx512_bf16" || flag == "amx_bf16") return true;
    }
    return false;
  }
  return false;
}

void copy_parameters(const torch::nn::Module& from, torch::nn::Module& to) {
  torch::NoGradGuard no_grad;
  const auto source = from.parameters();
  auto destination = to.parameters();
  for (std::size_t i = 0; i < source.size(); ++i) destination[i].copy_(source[i]);
}

void soft_update(const torch::nn::Module& from, torch::nn::Module& to, double tau) {
  torch::NoGradGuard no_grad;
  const auto source = from.parameters();
  auto destination = to.parameters();
  for (std::size_t i = 0; i < source.size(); ++i) destination[i].lerp_(source[i], tau);
}

std::vector<MemoryUse> off_policy_memory_estimate(const InputLayout& input,
                                                  const OffPolicySizes& config) {
  const auto d = [](std::int64_t value) { return static_cast<double>(value); };
  constexpr double kFloat = 4.0;
  // The encoder's activations per image (conv and ReLU outputs) and its output size.
  double activations = 0;
  double image_features = 0;
  double stack_bytes = 0;
  if (input.has_image) {
    double height = d(input.height);
    double width = d(input.width);
    for (const std::int64_t stride : encoder_strides(config.encoder)) {
      height = std::max(1.0, std::floor((height - 3) / d(stride)) + 1);
      width = std::max(1.0, std::floor((width - 3) / d(stride)) + 1);
      activations += 2 * 32 * height * width;
    }
    image_features = 32 * height * width;
    stack_bytes = d(input.stack) * d(input.height) * d(input.width) * d(input.channels);
  }
  double vector_size = 0;
  for (const std::int64_t size : input.vector_sizes) vector_size += d(size);
  const double features = image_features + vector_size;
  const double actions = d(input.action_size);
  const double hidden = d(config.hidden_dim);
  const double feature_dim = d(config.feature_dim);
  // Trained weights are kept four times (weights, gradients, Adam's two moments); the target
  // critic's once. Actor and critic trunks are trained, the target trunk is not.
  const double trunk = features * feature_dim + 3 * feature_dim;
  const double mlp_actor = feature_dim * hidden + hidden * hidden + hidden * actions;
  const double mlp_q = (feature_dim + actions) * hidden + hidden * hidden + hidden;
  const double trunk_bytes = kFloat * (4 * 2 * trunk + trunk);
  const double mlp_bytes = kFloat * (4 * (mlp_actor + 2 * mlp_q) + 2 * mlp_q);
  // Per sampled transition: its stacks and their shifted copies (obs and next obs), the float
  // images, the encoder's activations and their gradients (obs) and without (next obs), and the
  // MLPs' activations.
  const double per_sample = 4 * stack_bytes + 2 * kFloat * stack_bytes + 3 * kFloat * activations +
                            kFloat * 4 * (features + vector_size) +
                            kFloat * 24 * (hidden + feature_dim);
  // Per replay slot: the newest frame, the vector keys, the action, reward, flags, start.
  const double per_slot = stack_bytes / std::max<double>(1, d(input.stack)) +
                          kFloat * (vector_size + actions + 1) + 1 + 8;
  return {
      {"replay_capacity", d(config.replay_capacity), "the replay buffer",
       d(config.replay_capacity) * per_slot},
      {"batch_size", d(config.batch_size), "the sampled batches and the activations of an update",
       d(config.batch_size) * per_sample},
      {"hidden_dim", d(config.hidden_dim),
       "the actor's and critics' hidden layers (weights, gradients, Adam's moments, targets)",
       mlp_bytes},
      {"feature_dim", d(config.feature_dim),
       "the trunks from the encoder's " + std::to_string(static_cast<std::int64_t>(features)) +
           " features (weights, gradients, Adam's moments, target)",
       trunk_bytes},
  };
}

}  // namespace pixelgym::trainer
