// What the off-policy learners (DrQ, DrQ-v2) share beyond the encoder: the feature head and the
// MLPs of their actors and critics, the guarded optimizer step, bfloat16 autocast of the encoder
// where the CPU computes it natively, the target networks' copy and soft update, and the memory
// estimate that refuses settings which cannot fit.
#pragma once

#include <ATen/autocast_mode.h>
#include <torch/torch.h>

#include <cstdint>
#include <string>
#include <vector>

#include "examples/trainer/torch_common/conv_encoder.h"
#include "examples/trainer/torch_common/input_layout.h"
#include "pixelgym/trainer/memory_budget.h"

namespace pixelgym::trainer {

/// The head between the encoder and the MLPs: Linear(in, features), LayerNorm, tanh; its weights
/// orthogonal_init'ed with gain 1.
torch::nn::Sequential make_feature_head(std::int64_t in, std::int64_t features);

/// An MLP of `depth` hidden layers of `hidden` units, each Linear then ReLU, and a Linear to
/// `out`; its weights orthogonal_init'ed with gain sqrt(2). Its layers are named "0", "1", ... in
/// order, as checkpoints store them.
torch::nn::Sequential make_relu_mlp(std::int64_t in, std::int64_t hidden, std::int64_t depth,
                                    std::int64_t out);

/// One gradient step on `loss`, whose value the caller has read as `value`: throws
/// std::runtime_error "`what` is not finite (`value``detail`): no step taken" when it is NaN or
/// infinite; otherwise zeroes the gradients of every optimizer, back-propagates `loss` and steps
/// each optimizer in the order given.
void step_on_loss(const torch::Tensor& loss, double value, const std::string& what,
                  const std::vector<torch::optim::Optimizer*>& optimizers,
                  const std::string& detail = "");

/// Bfloat16 autocast of the CPU's operations for the scope of the guard (when `on`; otherwise it
/// does nothing). Keep it to convolutions: LayerNorm under CPU autocast fails in LibTorch 1.13.
class CpuAutocast {
 public:
  explicit CpuAutocast(bool on);
  ~CpuAutocast();
  CpuAutocast(const CpuAutocast&) = delete;
  CpuAutocast& operator=(const CpuAutocast&) = delete;

 private:
  bool on_;
  bool previous_ = false;
};

/// Whether this CPU computes bfloat16 natively (AVX512-BF16 or AMX-BF16), from /proc/cpuinfo.
bool cpu_has_bfloat16();

/// Copies `from`'s parameters into `to`'s (the same architecture), and moves `to`'s a fraction
/// `tau` of the way to `from`'s; neither records gradients.
void copy_parameters(const torch::nn::Module& from, torch::nn::Module& to);
void soft_update(const torch::nn::Module& from, torch::nn::Module& to, double tau);

/// The settings that size an off-policy learner's memory.
struct OffPolicySizes {
  std::int64_t replay_capacity = 0;
  /// Transitions encoded with gradients per update (a learner that encodes K shifted copies of
  /// each counts K times its batch).
  std::int64_t batch_size = 0;
  std::int64_t hidden_dim = 0;
  std::int64_t feature_dim = 0;
  EncoderArchitecture encoder = EncoderArchitecture::kMrq;
};

/// The memory a run of these sizes on `input` needs, by the setting that sets each part
/// (replay_capacity: the replay buffer; batch_size: the sampled batches, their copies and the
/// activations kept for backward; hidden_dim and feature_dim: the weights with their gradients,
/// Adam's moments and the target copies). An estimate within a factor of about 2, for refusing
/// settings that cannot fit (require_memory), not for planning to the byte.
std::vector<MemoryUse> off_policy_memory_estimate(const InputLayout& input,
                                                  const OffPolicySizes& config);

}  // namespace pixelgym::trainer
