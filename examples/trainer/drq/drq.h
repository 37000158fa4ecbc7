// DrQ (Kostrikov, Yarats and Fergus 2020): soft actor-critic from pixels, regularized by random
// shifts of the images. A squashed Gaussian actor, clipped double Q with a target critic, a
// learned entropy temperature, and K random shifts of current and next observations averaged.
// The config, the networks and one update.
#pragma once

#include <torch/torch.h>

#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <type_traits>
#include <vector>

#include "examples/trainer/torch_common/conv_encoder.h"
#include "examples/trainer/torch_common/input_layout.h"
#include "examples/trainer/torch_common/off_policy_agent.h"
#include "examples/trainer/torch_common/off_policy_settings.h"
#include "examples/trainer/torch_common/replay_buffer.h"

namespace pixelgym::drq {

using trainer::EncoderArchitecture;
using trainer::InputLayout;
using trainer::ObservationView;
using trainer::ReplayBatch;
using trainer::ReplayBuffer;

/// Every setting of the learner (the shared off-policy ones, torch_common/off_policy_settings.h,
/// and DrQ's own); validate() checks each. The defaults are DrQ's published
/// ones (its config.yaml: learning rate 1e-3, batch 128 (512 in the paper), initial
/// temperature 0.1, target entropy -|A|, actor and target updates every second update, tau 0.01,
/// features 50, log std in [-10, 2], 1000 seed steps, one update per env step, pad 4, 3 frames)
/// except where a CPU needs less: hidden 256 (DrQ: 1024), MR.Q's encoder (DrQ: strides
/// 2, 1, 1, 1) and one shifted copy (DrQ: K = M = 2); docs/experiments/drq.md measures each.
struct DrqConfig : trainer::OffPolicySettings {
  /// DrQ's 1-step returns (the shared default is DrQ-v2's 3).
  DrqConfig() { n_step = 1; }

  /// The entropy temperature alpha starts here and is learned towards target_entropy (NaN: -|A|,
  /// SAC's choice).
  double init_temperature = 0.1;
  double target_entropy = std::numeric_limits<double>::quiet_NaN();
  /// The actor and the temperature are updated every actor_update_every updates; the target
  /// critic moves critic_tau towards the critic every target_update_every updates.
  std::int64_t actor_update_every = 2;
  std::int64_t target_update_every = 2;
  /// Hidden layers of each MLP (of hidden_dim).
  std::int64_t hidden_depth = 2;
  /// The actor's log standard deviation is squashed into [log_std_min, log_std_max].
  double log_std_min = -10.0;
  double log_std_max = 2.0;
  /// How many shifted copies of each observation and next observation an update averages its
  /// target and loss over (DrQ's K and M, equal here).
  std::int64_t augmented_copies = 1;

  /// Throws std::invalid_argument naming the first member out of range and its value.
  void validate() const;
  /// target_entropy, or -action_size when it is NaN.
  double entropy_target(std::int64_t action_size) const;
};

/// DrqConfig's settings, declared once (pixelgym/trainer/settings_declaration.h): the shared
/// off-policy ones, then DrQ's own. Its JSON form, its ranges and `train --list-settings` come
/// from here.
template <typename Config, typename Visit>
std::enable_if_t<std::is_same_v<std::remove_const_t<Config>, DrqConfig>> declare_settings(
    Config& c, Visit& visit) {
  trainer::declare_off_policy_settings(c, visit);
  visit.number("init_temperature", c.init_temperature, 1e-8, 1e8,
               "the entropy temperature alpha at the start (it is learned)");
  visit.optional_number("target_entropy", c.target_entropy, -1e6, 1e6,
                        "the entropy alpha steers the policy towards (null: -|A|, SAC's)");
  visit.count("actor_update_every", c.actor_update_every, 1,
              "the actor and alpha are updated every this many updates");
  visit.count("target_update_every", c.target_update_every, 1,
              "the target critic moves critic_tau towards the critic every this many updates");
  visit.count("hidden_depth", c.hidden_depth, 1, "hidden layers of each MLP");
  visit.number("log_std_min", c.log_std_min, -20.0, 5.0,
               "the lower bound of the actor's log standard deviation");
  visit.number("log_std_max", c.log_std_max, -20.0, 5.0, "its upper bound (at least log_std_min)");
  visit.integer("augmented_copies", c.augmented_copies, std::int64_t{1}, std::int64_t{8},
                "shifted copies of each observation and next observation that an update "
                "averages over (DrQ's K = M)");
}

/// JSON form: one member per field (target_entropy null for NaN). from_json takes any subset and
/// throws std::invalid_argument for an unknown member, a wrong type or a config failing
/// validate().
void to_json(nlohmann::json& json, const DrqConfig& config);
void from_json(const nlohmann::json& json, DrqConfig& config);

/// A squashed Gaussian's sample: the action in [-1, 1] and its log-probability (summed over the
/// action's elements, with tanh's change of variables).
struct PolicySample {
  torch::Tensor action;
  torch::Tensor log_prob;
};

/// The encoder (shared by actor and critic, trained by the critic), the actor, the critic and the
/// target critic. From images each network reads the encoder's features through a head of its
/// own (Linear, LayerNorm, tanh to feature_dim), the vector keys beside them; from vectors
/// alone it reads them directly, as SAC from state does. Built from torch's default generator
/// (call torch::manual_seed first); orthogonal weights and zero biases. The input, the encoder's
/// pass and the action bounds are the shared OffPolicyAgent's.
class Agent : public trainer::OffPolicyAgent {
 public:
  Agent(InputLayout input, const DrqConfig& config);

  /// The actor's, the critic's or the target critic's input: its head over the encoder's output
  /// (convolve's) beside the vectors (either may be undefined).
  torch::Tensor actor_features(const torch::Tensor& conv, const torch::Tensor& vectors);
  torch::Tensor critic_features(const torch::Tensor& conv, const torch::Tensor& vectors,
                                bool target);
  /// The policy's mean action (tanh of the Gaussian's mean), and a reparameterized sample.
  torch::Tensor mean_action(const torch::Tensor& features);
  PolicySample sample(const torch::Tensor& features, at::Generator& generator);
  /// Q1 and Q2 (B) of the critic or the target critic.
  std::pair<torch::Tensor, torch::Tensor> q_values(const torch::Tensor& features,
                                                   const torch::Tensor& actions, bool target);
  /// The mean when `deterministic` or `generator` is null, else a sample.
  torch::Tensor act(const trainer::ObservationTensors& obs, bool deterministic,
                    at::Generator* generator) override;
  /// From vectors alone, `actor`: its first half is the Gaussian's mean.
  torch::nn::Sequential policy_mlp() const override { return input().has_image ? nullptr : actor; }

  torch::nn::Sequential actor_head{nullptr}, critic_head{nullptr}, target_head{nullptr};
  torch::nn::Sequential actor{nullptr}, q1{nullptr}, q2{nullptr}, target_q1{nullptr},
      target_q2{nullptr};
  torch::Tensor log_alpha;

 private:
  double log_std_min_, log_std_max_;
};

/// What one update did (NaN where a part was not updated).
struct UpdateStats {
  double critic_loss = 0.0;
  double actor_loss = 0.0;
  double alpha = 0.0;
  double entropy = 0.0;  // minus the mean log-probability of the actor's samples
  double q_mean = 0.0;
  double target_mean = 0.0;
};

/// The learner: an Agent, its Adams (critic with encoder, actor, temperature) and the update.
class Learner {
 public:
  /// Seeds torch with config.seed before building the agent.
  Learner(InputLayout input, DrqConfig config);

  /// One update from `batch`: generators for the shifts and the policy's samples. Throws
  /// std::runtime_error naming the loss when one is not finite; no step is taken then.
  UpdateStats update(const ReplayBatch& batch, at::Generator& augmentation,
                     at::Generator& sampling);

  Agent& agent() { return *agent_; }
  const std::shared_ptr<Agent>& agent_ptr() const { return agent_; }
  torch::optim::Adam& critic_optimizer() { return *critic_optimizer_; }
  torch::optim::Adam& actor_optimizer() { return *actor_optimizer_; }
  torch::optim::Adam& alpha_optimizer() { return *alpha_optimizer_; }
  std::int64_t updates() const { return updates_; }
  void set_updates(std::int64_t updates) { updates_ = updates; }
  const DrqConfig& config() const { return config_; }

 private:
  DrqConfig config_;
  std::shared_ptr<Agent> agent_;
  std::unique_ptr<torch::optim::Adam> critic_optimizer_, actor_optimizer_, alpha_optimizer_;
  std::vector<std::uint8_t> shifted_;
  std::int64_t updates_ = 0;
  double target_entropy_ = 0.0;
};

}  // namespace pixelgym::drq
