// DrQ-v2 (Yarats et al. 2021): DDPG from pixels with a twin critic and its target, n-step
// returns from a replay buffer, random-shift augmentation and a scheduled exploration noise.
// The config, the networks and one update.
#pragma once

#include <torch/torch.h>

#include <cstdint>
#include <map>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <type_traits>
#include <vector>

#include "examples/trainer/torch_common/conv_encoder.h"
#include "examples/trainer/torch_common/input_layout.h"
#include "examples/trainer/torch_common/off_policy_agent.h"
#include "examples/trainer/torch_common/off_policy_networks.h"
#include "examples/trainer/torch_common/off_policy_settings.h"
#include "examples/trainer/torch_common/random_shift.h"
#include "examples/trainer/torch_common/replay_buffer.h"
#include "pixelgym/envs/space.h"
#include "pixelgym/trainer/memory_budget.h"

namespace pixelgym::drqv2 {

/// The shared torch layer's encoder, input layout, replay buffer and random shift, by the names
/// DrQ-v2's code and tests use (examples/trainer/torch_common/).
using trainer::encoder_strides;
using trainer::EncoderArchitecture;
using trainer::input_layout;
using trainer::InputLayout;
using trainer::ObservationView;
using trainer::parse_encoder_architecture;
using trainer::ReplayBatch;
using trainer::ReplayBuffer;
using trainer::ReplayLayout;
using trainer::shift_frames;
using trainer::to_string;

/// Every setting of the learner (the shared off-policy ones, torch_common/off_policy_settings.h,
/// and DrQ-v2's own); validate() checks each. The defaults follow DrQ-v2
/// (3-step returns, tau 0.01, features 50, noise clip 0.3) with DrQ's learning rate 1e-3 and
/// one update per env step (DrQ's at action repeat 4 to 8), a smaller batch (128, not 256) and
/// MLPs (256, not 1024) for a CPU, and TD7's penalty on the actor's pre-tanh values: at DrQ-v2's
/// learning rate 1e-4 a 100k-control-step run makes too few updates, and at 1e-3 without the
/// penalty the policy saturated from pixels (docs/drqv2.md, Results).
struct DrqV2Config : trainer::OffPolicySettings {
  /// The exploration noise's standard deviation: noise_start, linearly to noise_end over
  /// noise_schedule_env_steps env steps, then noise_end. The target policy's and the actor
  /// loss's noise is clipped to +-noise_clip.
  double noise_start = 1.0;
  double noise_end = 0.1;
  std::int64_t noise_schedule_env_steps = 25'000;
  double noise_clip = 0.3;
  /// The actor's loss adds this times the mean square of the values its tanh is taken of (as
  /// TD7 and MR.Q do): a policy pushed into tanh's flat tails, where the critic's gradient
  /// vanishes, is pulled back. 0: none.
  double actor_preactivation_penalty = 1e-3;

  /// Throws std::invalid_argument naming the first member out of range and its value.
  void validate() const;
  /// The noise's standard deviation after `env_steps`.
  double noise_std(std::int64_t env_steps) const;
};

/// DrqV2Config's settings, declared once (pixelgym/trainer/settings_declaration.h): the shared
/// off-policy ones, then DrQ-v2's own. Its JSON form, its ranges and `train --list-settings`
/// come from here.
template <typename Config, typename Visit>
std::enable_if_t<std::is_same_v<std::remove_const_t<Config>, DrqV2Config>> declare_settings(
    Config& c, Visit& visit) {
  trainer::declare_off_policy_settings(c, visit);
  visit.number("noise_start", c.noise_start, 0.0, 10.0,
               "the exploration noise's standard deviation at the start");
  visit.number("noise_end", c.noise_end, 0.0, 10.0,
               "its standard deviation once noise_schedule_env_steps have passed (linearly in "
               "between), and the stochastic evaluation's");
  visit.count("noise_schedule_env_steps", c.noise_schedule_env_steps, 0,
              "env steps over which the noise goes from noise_start to noise_end");
  visit.number("noise_clip", c.noise_clip, 0.0, 10.0,
               "the target policy's and the actor loss's noise is clipped to +-noise_clip");
  visit.number("actor_preactivation_penalty", c.actor_preactivation_penalty, 0.0, 1e3,
               "the actor's loss adds this times the mean square of what its tanh is taken of "
               "(TD7's and MR.Q's pull away from tanh's flat tails; 0: none)");
}

/// JSON form: one member per field, named as the fields, the encoder by its name. from_json
/// takes any subset (the rest keep their defaults) and throws std::invalid_argument for an
/// unknown member (listing the known ones), a member of the wrong type, or a config that fails
/// validate().
void to_json(nlohmann::json& json, const DrqV2Config& config);
void from_json(const nlohmann::json& json, DrqV2Config& config);

/// Whether this CPU computes bfloat16 natively (torch_common/off_policy_networks.h).
using trainer::cpu_has_bfloat16;

/// The memory a run of `config` on inputs `input` needs, by the member that sets each part
/// (replay_capacity: the replay buffer; batch_size: the sampled batches, their copies and the
/// activations kept for backward; hidden_dim and feature_dim: the weights with their gradients,
/// Adam's moments and the target copies). An estimate within a factor of about 2, for refusing
/// settings that cannot fit (trainer::require_memory), not for planning to the byte.
std::vector<trainer::MemoryUse> memory_estimate(const InputLayout& input,
                                                const DrqV2Config& config);

/// The encoder, actor, critic and target critic. Built from torch's default generator (call
/// torch::manual_seed first). Orthogonal weights (gain sqrt(2) before ReLU, else 1), zero
/// biases, as DrQ-v2.
class Agent : public trainer::OffPolicyAgent {
 public:
  Agent(InputLayout input, const DrqV2Config& config);

  /// Features of a batch: the encoder over float images (B, stack C, H, W) in [0, 255]
  /// (undefined: no image) beside the vector keys (B, sum of sizes; undefined: none).
  torch::Tensor encode(const torch::Tensor& images, const torch::Tensor& vectors);
  /// The policy's action in [-1, 1] (tanh) for features, and what the tanh is taken of.
  torch::Tensor actor_mean(const torch::Tensor& features);
  torch::Tensor actor_preactivation(const torch::Tensor& features);
  /// Q1 and Q2 of the critic (or of the target critic) for features and actions in [-1, 1].
  std::pair<torch::Tensor, torch::Tensor> q_values(const torch::Tensor& features,
                                                   const torch::Tensor& actions, bool target);
  /// Actions in [-1, 1] for a batch of observations (a vector env's, as
  /// trainer::observation_tensors gives them): the policy's mean when `deterministic` or `noise` is
  /// null, else the mean plus Gaussian noise of std `noise_std` drawn from `noise`, clamped.
  /// Computes no gradients.
  torch::Tensor act(const trainer::ObservationTensors& obs, bool deterministic, double noise_std,
                    at::Generator* noise);
  /// The same with noise of std noise_end (the evaluation's stochastic actions).
  torch::Tensor act(const trainer::ObservationTensors& obs, bool deterministic,
                    at::Generator* noise) override;

  std::int64_t feature_size() const { return feature_size_; }

  torch::nn::Sequential actor_trunk{nullptr}, actor_head{nullptr};
  torch::nn::Sequential critic_trunk{nullptr}, q1{nullptr}, q2{nullptr};
  torch::nn::Sequential target_trunk{nullptr}, target_q1{nullptr}, target_q2{nullptr};

 private:
  std::int64_t feature_size_ = 0;
  double evaluation_noise_std_ = 0.0;
};

/// What one update did.
struct UpdateStats {
  double critic_loss = 0.0;
  double actor_loss = 0.0;
  double q_mean = 0.0;       // mean of Q1 over the batch
  double target_mean = 0.0;  // mean of the n-step target
};

/// Where an update's time went (seconds), filled when profiling.
struct UpdateTimes {
  double sample = 0.0;    // ReplayBuffer::sample and the copy to tensors
  double augment = 0.0;   // random shifts of obs and next obs
  double encode = 0.0;    // the encoder forward on obs and next obs
  double critic = 0.0;    // target, critic forward and loss
  double backward = 0.0;  // critic and encoder backward and their Adam steps
  double actor = 0.0;     // actor forward, loss, backward, step
  double target = 0.0;    // the target critic's soft update
};

/// The learner: an Agent, its three Adams (encoder, actor, critic) and the update.
class Learner {
 public:
  /// Seeds torch with config.seed before building the agent. Throws as input_layout's checks.
  Learner(InputLayout input, DrqV2Config config);

  /// One update from `batch` at `env_steps` (the noise's schedule); generators for the
  /// augmentation and the noise. When `times` is given, synchronous timings of its phases are
  /// added to it. Throws std::runtime_error (naming the losses) when a loss is not finite; no
  /// step is taken then.
  UpdateStats update(const ReplayBatch& batch, std::int64_t env_steps, at::Generator& augmentation,
                     at::Generator& noise, UpdateTimes* times = nullptr);
  Agent& agent() { return *agent_; }
  const std::shared_ptr<Agent>& agent_ptr() const { return agent_; }
  /// Null when the observation has no image (no encoder).
  torch::optim::Adam* encoder_optimizer() { return encoder_optimizer_.get(); }
  torch::optim::Adam& actor_optimizer() { return *actor_optimizer_; }
  torch::optim::Adam& critic_optimizer() { return *critic_optimizer_; }
  const DrqV2Config& config() const { return config_; }

 private:
  DrqV2Config config_;
  std::shared_ptr<Agent> agent_;
  std::unique_ptr<torch::optim::Adam> encoder_optimizer_, actor_optimizer_, critic_optimizer_;
  std::vector<std::uint8_t> shifted_, next_shifted_;  // the batch's images, shifted
};

}  // namespace pixelgym::drqv2
