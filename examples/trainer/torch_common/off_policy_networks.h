// What the off-policy learners (DrQ, DrQ-v2) share beyond the encoder: bfloat16 autocast of the
// encoder where the CPU computes it natively, the target networks' copy and soft update, and the
// memory estimate that refuses settings which cannot fit.
#pragma once

#include <ATen/autocast_mode.h>
#include <torch/torch.h>

#include <cstdint>
#include <vector>

#include "examples/trainer/torch_common/conv_encoder.h"
#include "examples/trainer/torch_common/input_layout.h"
#include "pixelgym/trainer/memory_budget.h"

namespace pixelgym::trainer {

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
