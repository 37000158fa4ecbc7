#include "examples/trainer/drqv2/drqv2.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "examples/trainer/torch_common/off_policy_networks.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/trainer/config_members.h"

namespace pixelgym::drqv2 {
namespace {

using trainer::copy_parameters;
using trainer::soft_update;

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

constexpr const char* kConfigName = "DrqV2Config";

}  // namespace

void DrqV2Config::validate() const {
  trainer::check_settings(*this, kConfigName);
  trainer::validate_off_policy_settings(*this, trainer::ConfigChecks(kConfigName));
}

double DrqV2Config::noise_std(std::int64_t env_steps) const {
  if (noise_schedule_env_steps == 0 || env_steps >= noise_schedule_env_steps) return noise_end;
  const double progress =
      static_cast<double>(env_steps) / static_cast<double>(noise_schedule_env_steps);
  return noise_start + (noise_end - noise_start) * progress;
}

void to_json(nlohmann::json& json, const DrqV2Config& config) {
  trainer::write_settings(json, config);
}

void from_json(const nlohmann::json& json, DrqV2Config& config) {
  trainer::read_settings(json, config, kConfigName);
  config.validate();
}

// ---- Agent -----------------------------------------------------------------------------------

std::vector<trainer::MemoryUse> memory_estimate(const InputLayout& input,
                                                const DrqV2Config& config) {
  return trainer::off_policy_memory_estimate(
      input, {config.replay_capacity, config.batch_size, config.hidden_dim, config.feature_dim,
              config.encoder});
}

Agent::Agent(InputLayout input, const DrqV2Config& config)
    : OffPolicyAgent(std::move(input), config), evaluation_noise_std_(config.noise_end) {
  const InputLayout& layout = this->input();
  const std::int64_t image_features = register_encoder(config.encoder, "drqv2");
  std::int64_t vector_features = 0;
  for (const std::int64_t size : layout.vector_sizes) vector_features += size;
  feature_size_ = image_features + vector_features;
  if (feature_size_ == 0) throw std::invalid_argument("drqv2: the observation has no input");
  const std::int64_t features = config.feature_dim;
  const std::int64_t actions = layout.action_size;
  actor_trunk = register_module("actor_trunk", trainer::make_feature_head(feature_size_, features));
  actor_head = register_module("actor_head",
                               trainer::make_relu_mlp(features, config.hidden_dim, 2, actions));
  critic_trunk =
      register_module("critic_trunk", trainer::make_feature_head(feature_size_, features));
  q1 = register_module("q1", trainer::make_relu_mlp(features + actions, config.hidden_dim, 2, 1));
  q2 = register_module("q2", trainer::make_relu_mlp(features + actions, config.hidden_dim, 2, 1));
  target_trunk =
      register_module("target_trunk", trainer::make_feature_head(feature_size_, features));
  target_q1 = register_module("target_q1",
                              trainer::make_relu_mlp(features + actions, config.hidden_dim, 2, 1));
  target_q2 = register_module("target_q2",
                              trainer::make_relu_mlp(features + actions, config.hidden_dim, 2, 1));
  copy_parameters(*critic_trunk, *target_trunk);
  copy_parameters(*q1, *target_q1);
  copy_parameters(*q2, *target_q2);
  for (auto* target : {&target_trunk, &target_q1, &target_q2}) {
    for (auto& parameter : (*target)->parameters()) parameter.set_requires_grad(false);
  }
}

torch::Tensor Agent::encode(const torch::Tensor& images, const torch::Tensor& vectors) {
  std::vector<torch::Tensor> parts;
  if (input().has_image) parts.push_back(convolve(images));
  if (vectors.defined()) parts.push_back(vectors);
  return parts.size() == 1 ? parts[0] : torch::cat(parts, 1);
}

torch::Tensor Agent::actor_preactivation(const torch::Tensor& features) {
  return actor_head->forward(actor_trunk->forward(features));
}

torch::Tensor Agent::actor_mean(const torch::Tensor& features) {
  return torch::tanh(actor_preactivation(features));
}

std::pair<torch::Tensor, torch::Tensor> Agent::q_values(const torch::Tensor& features,
                                                        const torch::Tensor& actions, bool target) {
  const torch::Tensor h = (target ? target_trunk : critic_trunk)->forward(features);
  const torch::Tensor input = torch::cat({h, actions}, 1);
  return {(target ? target_q1 : q1)->forward(input).squeeze(1),
          (target ? target_q2 : q2)->forward(input).squeeze(1)};
}

// ---- Learner ---------------------------------------------------------------------------------

namespace {

torch::Tensor clipped_noise(const torch::Tensor& like, double std, double clip,
                            at::Generator& generator) {
  return (torch::randn(like.sizes(), generator, like.options()) * std).clamp(-clip, clip);
}

}  // namespace

Learner::Learner(InputLayout input, DrqV2Config config)
    : config_(std::move(config)), agent_(trainer::make_agent<Agent>(std::move(input), config_)) {
  const auto adam = [&](std::vector<torch::Tensor> parameters) {
    return std::make_unique<torch::optim::Adam>(std::move(parameters),
                                                torch::optim::AdamOptions(config_.learning_rate));
  };
  if (agent_->input().has_image) encoder_optimizer_ = adam(agent_->encoder->parameters());
  actor_optimizer_ = adam(
      trainer::parameters_of({agent_->actor_trunk.ptr().get(), agent_->actor_head.ptr().get()}));
  critic_optimizer_ = adam(trainer::parameters_of(
      {agent_->critic_trunk.ptr().get(), agent_->q1.ptr().get(), agent_->q2.ptr().get()}));
}

UpdateStats Learner::update(const ReplayBatch& batch, std::int64_t env_steps,
                            at::Generator& augmentation, at::Generator& noise, UpdateTimes* times) {
  Agent& agent = *agent_;
  const InputLayout& input = agent.input();
  const std::int64_t size = batch.size;
  auto clock = Clock::now();
  const auto lap = [&](double UpdateTimes::*phase) {
    if (times == nullptr) return;
    times->*phase += seconds_since(clock);
    clock = Clock::now();
  };
  // Inputs, augmented.
  torch::Tensor images, next_images;
  if (input.has_image) {
    const std::int64_t pad = config_.shift_pad;
    images = agent.shifted_images(batch.images[0], size, pad, augmentation, shifted_);
    next_images =
        agent.shifted_images(batch.next_images[0], size, pad, augmentation, next_shifted_);
  }
  const torch::Tensor vectors = trainer::batch_vectors(batch.vectors, input, size);
  const torch::Tensor next_vectors = trainer::batch_vectors(batch.next_vectors, input, size);
  const torch::Tensor actions =
      trainer::view_of(batch.actions, {size, input.action_size}, torch::kFloat32);
  const torch::Tensor rewards = trainer::view_of(batch.rewards, {size}, torch::kFloat32);
  const torch::Tensor discounts = trainer::view_of(batch.discounts, {size}, torch::kFloat32);
  lap(&UpdateTimes::augment);

  const torch::Tensor features = agent.encode(images, vectors);
  torch::Tensor next_features;
  {
    torch::NoGradGuard no_grad;
    next_features = agent.encode(next_images, next_vectors);
  }
  lap(&UpdateTimes::encode);

  // Critic: the n-step target from the target critic at the target policy's noisy action.
  const double std = config_.noise_std(env_steps);
  torch::Tensor target;
  {
    torch::NoGradGuard no_grad;
    const torch::Tensor mean = agent.actor_mean(next_features);
    const torch::Tensor next_action =
        (mean + clipped_noise(mean, std, config_.noise_clip, noise)).clamp(-1.0, 1.0);
    const auto [target_q1, target_q2] = agent.q_values(next_features, next_action, true);
    target = rewards + discounts * torch::min(target_q1, target_q2);
  }
  const auto [q1, q2] = agent.q_values(features, actions, false);
  const torch::Tensor critic_loss = torch::mse_loss(q1, target) + torch::mse_loss(q2, target);
  UpdateStats stats;
  stats.critic_loss = critic_loss.item<double>();
  stats.q_mean = q1.mean().item<double>();
  stats.target_mean = target.mean().item<double>();
  lap(&UpdateTimes::critic);
  std::vector<torch::optim::Optimizer*> critic_step{critic_optimizer_.get()};
  if (encoder_optimizer_) critic_step.push_back(encoder_optimizer_.get());
  trainer::step_on_loss(critic_loss, stats.critic_loss, "drqv2: the critic loss", critic_step,
                        ", Q mean " + std::to_string(stats.q_mean));
  lap(&UpdateTimes::backward);

  // Actor: the critic's value of the policy's noisy action, on features the actor cannot move.
  const torch::Tensor detached = features.detach();
  const torch::Tensor preactivation = agent.actor_preactivation(detached);
  const torch::Tensor mean = torch::tanh(preactivation);
  const torch::Tensor action =
      (mean + clipped_noise(mean, std, config_.noise_clip, noise)).clamp(-1.0, 1.0);
  const auto [actor_q1, actor_q2] = agent.q_values(detached, action, false);
  torch::Tensor actor_loss = -torch::min(actor_q1, actor_q2).mean();
  if (config_.actor_preactivation_penalty > 0.0) {
    actor_loss = actor_loss + config_.actor_preactivation_penalty * preactivation.square().mean();
  }
  stats.actor_loss = actor_loss.item<double>();
  trainer::step_on_loss(actor_loss, stats.actor_loss, "drqv2: the actor loss",
                        {actor_optimizer_.get()});
  lap(&UpdateTimes::actor);

  soft_update(*agent.critic_trunk, *agent.target_trunk, config_.critic_tau);
  soft_update(*agent.q1, *agent.target_q1, config_.critic_tau);
  soft_update(*agent.q2, *agent.target_q2, config_.critic_tau);
  lap(&UpdateTimes::target);
  return stats;
}

torch::Tensor Agent::act(const trainer::ObservationTensors& obs, bool deterministic,
                         double noise_std, at::Generator* noise) {
  torch::NoGradGuard no_grad;
  const trainer::AgentInput in = observation_input(obs);
  const torch::Tensor mean = actor_mean(encode(in.images, in.vectors));
  if (deterministic || noise == nullptr) return mean;
  return (mean + torch::randn(mean.sizes(), *noise, mean.options()) * noise_std).clamp(-1.0, 1.0);
}

torch::Tensor Agent::act(const trainer::ObservationTensors& obs, bool deterministic,
                         at::Generator* noise) {
  return act(obs, deterministic, evaluation_noise_std_, noise);
}

}  // namespace pixelgym::drqv2
