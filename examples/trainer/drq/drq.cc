#include "examples/trainer/drq/drq.h"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "examples/trainer/torch_common/off_policy_networks.h"
#include "pixelgym/trainer/config_members.h"

namespace pixelgym::drq {
namespace {

constexpr const char* kConfigName = "DrqConfig";

using trainer::copy_parameters;
using trainer::soft_update;

using trainer::batch_vectors;
using trainer::view_of;

torch::Tensor beside(const torch::Tensor& head, const torch::Tensor& vectors) {
  if (!head.defined()) return vectors;
  if (!vectors.defined()) return head;
  return torch::cat({head, vectors}, 1);
}

}  // namespace

void DrqConfig::validate() const {
  trainer::check_settings(*this, kConfigName);
  const trainer::ConfigChecks checks(kConfigName);
  trainer::validate_off_policy_settings(*this, checks);
  checks.in_range("log_std_max", log_std_max, log_std_min, 5.0);
}

double DrqConfig::entropy_target(std::int64_t action_size) const {
  return std::isnan(target_entropy) ? -static_cast<double>(action_size) : target_entropy;
}

void to_json(nlohmann::json& json, const DrqConfig& config) {
  trainer::write_settings(json, config);
}

void from_json(const nlohmann::json& json, DrqConfig& config) {
  trainer::read_settings(json, config, kConfigName);
  config.validate();
}

// ---- Agent -----------------------------------------------------------------------------------

Agent::Agent(InputLayout input, const DrqConfig& config)
    : OffPolicyAgent(std::move(input), config),
      log_std_min_(config.log_std_min),
      log_std_max_(config.log_std_max) {
  const InputLayout& layout = this->input();
  std::int64_t features = 0;
  const std::int64_t conv_features = register_encoder(config.encoder, "drq");
  if (layout.has_image) {
    actor_head = register_module("actor_head",
                                 trainer::make_feature_head(conv_features, config.feature_dim));
    critic_head = register_module("critic_head",
                                  trainer::make_feature_head(conv_features, config.feature_dim));
    target_head = register_module("target_head",
                                  trainer::make_feature_head(conv_features, config.feature_dim));
    copy_parameters(*critic_head, *target_head);
    features += config.feature_dim;
  }
  for (const std::int64_t size : layout.vector_sizes) features += size;
  if (features == 0) throw std::invalid_argument("drq: the observation has no input");
  const std::int64_t actions = layout.action_size;
  const std::int64_t hidden = config.hidden_dim;
  const std::int64_t depth = config.hidden_depth;
  actor = register_module("actor", trainer::make_relu_mlp(features, hidden, depth, 2 * actions));
  q1 = register_module("q1", trainer::make_relu_mlp(features + actions, hidden, depth, 1));
  q2 = register_module("q2", trainer::make_relu_mlp(features + actions, hidden, depth, 1));
  target_q1 =
      register_module("target_q1", trainer::make_relu_mlp(features + actions, hidden, depth, 1));
  target_q2 =
      register_module("target_q2", trainer::make_relu_mlp(features + actions, hidden, depth, 1));
  copy_parameters(*q1, *target_q1);
  copy_parameters(*q2, *target_q2);
  for (auto* target : {&target_head, &target_q1, &target_q2}) {
    if (!*target) continue;
    for (auto& parameter : (*target)->parameters()) parameter.set_requires_grad(false);
  }
  log_alpha = register_parameter(
      "log_alpha", torch::full({1}, std::log(config.init_temperature), torch::kFloat32));
}

torch::Tensor Agent::actor_features(const torch::Tensor& conv, const torch::Tensor& vectors) {
  return beside(conv.defined() ? actor_head->forward(conv) : torch::Tensor(), vectors);
}

torch::Tensor Agent::critic_features(const torch::Tensor& conv, const torch::Tensor& vectors,
                                     bool target) {
  if (!conv.defined()) return vectors;
  return beside((target ? target_head : critic_head)->forward(conv), vectors);
}

torch::Tensor Agent::mean_action(const torch::Tensor& features) {
  return torch::tanh(actor->forward(features).chunk(2, 1)[0]);
}

PolicySample Agent::sample(const torch::Tensor& features, at::Generator& generator) {
  const auto parts = actor->forward(features).chunk(2, 1);
  const torch::Tensor& mean = parts[0];
  const torch::Tensor log_std =
      log_std_min_ + 0.5 * (log_std_max_ - log_std_min_) * (torch::tanh(parts[1]) + 1.0);
  const torch::Tensor eps = torch::randn(mean.sizes(), generator, mean.options());
  const torch::Tensor x = mean + eps * log_std.exp();
  // log N(x; mean, std) - log(1 - tanh(x)^2), the latter as 2 (log 2 - x - softplus(-2x)).
  const double half_log_2pi = 0.5 * std::log(2.0 * M_PI);
  const torch::Tensor gaussian = -0.5 * eps.square() - log_std - half_log_2pi;
  const torch::Tensor squash = 2.0 * (std::log(2.0) - x - torch::softplus(-2.0 * x));
  return {torch::tanh(x), (gaussian - squash).sum(1)};
}

std::pair<torch::Tensor, torch::Tensor> Agent::q_values(const torch::Tensor& features,
                                                        const torch::Tensor& actions, bool target) {
  const torch::Tensor input = torch::cat({features, actions}, 1);
  return {(target ? target_q1 : q1)->forward(input).squeeze(1),
          (target ? target_q2 : q2)->forward(input).squeeze(1)};
}

torch::Tensor Agent::act(const trainer::ObservationTensors& obs, bool deterministic,
                         at::Generator* generator) {
  torch::NoGradGuard no_grad;
  const trainer::AgentInput in = observation_input(obs);
  const torch::Tensor features = actor_features(convolve(in.images), in.vectors);
  if (deterministic || generator == nullptr) return mean_action(features);
  return sample(features, *generator).action;
}

// ---- Learner ---------------------------------------------------------------------------------

Learner::Learner(InputLayout input, DrqConfig config)
    : config_(std::move(config)), agent_(trainer::make_agent<Agent>(std::move(input), config_)) {
  Agent& agent = *agent_;
  target_entropy_ = config_.entropy_target(agent.input().action_size);
  const auto adam = [&](std::vector<torch::Tensor> parameters) {
    return std::make_unique<torch::optim::Adam>(std::move(parameters),
                                                torch::optim::AdamOptions(config_.learning_rate));
  };
  critic_optimizer_ =
      adam(trainer::parameters_of({agent.encoder ? agent.encoder.ptr().get() : nullptr,
                                   agent.critic_head ? agent.critic_head.ptr().get() : nullptr,
                                   agent.q1.ptr().get(), agent.q2.ptr().get()}));
  actor_optimizer_ = adam(trainer::parameters_of(
      {agent.actor_head ? agent.actor_head.ptr().get() : nullptr, agent.actor.ptr().get()}));
  alpha_optimizer_ = adam({agent.log_alpha});
}

UpdateStats Learner::update(const ReplayBatch& batch, at::Generator& augmentation,
                            at::Generator& sampling) {
  Agent& agent = *agent_;
  const InputLayout& input = agent.input();
  const std::int64_t size = batch.size;
  const std::int64_t copies = input.has_image ? config_.augmented_copies : 1;
  const auto shifted = [&](const std::vector<std::uint8_t>& stacks) {
    return agent.shifted_images(stacks, size, config_.shift_pad, augmentation, shifted_);
  };
  const torch::Tensor vectors = batch_vectors(batch.vectors, input, size);
  const torch::Tensor next_vectors = batch_vectors(batch.next_vectors, input, size);
  const torch::Tensor actions = view_of(batch.actions, {size, input.action_size}, torch::kFloat32);
  const torch::Tensor rewards = view_of(batch.rewards, {size}, torch::kFloat32);
  const torch::Tensor discounts = view_of(batch.discounts, {size}, torch::kFloat32);
  const torch::Tensor alpha = agent.log_alpha.exp().detach();

  // The target: the mean over the shifted copies of the next observation of the target critic's
  // soft value at the policy's sample.
  torch::Tensor target;
  {
    torch::NoGradGuard no_grad;
    torch::Tensor sum;
    for (std::int64_t k = 0; k < copies; ++k) {
      const torch::Tensor conv =
          input.has_image ? agent.convolve(shifted(batch.next_images[0])) : torch::Tensor();
      const PolicySample next = agent.sample(agent.actor_features(conv, next_vectors), sampling);
      const auto [target_q1, target_q2] =
          agent.q_values(agent.critic_features(conv, next_vectors, true), next.action, true);
      const torch::Tensor value = torch::min(target_q1, target_q2) - alpha * next.log_prob;
      sum = k == 0 ? value : sum + value;
    }
    target = rewards + discounts * sum / static_cast<double>(copies);
  }
  // The critic, on each shifted copy of the observation.
  torch::Tensor critic_loss;
  torch::Tensor first_conv;
  double q_sum = 0.0;
  for (std::int64_t k = 0; k < copies; ++k) {
    const torch::Tensor conv =
        input.has_image ? agent.convolve(shifted(batch.images[0])) : torch::Tensor();
    if (k == 0) first_conv = conv;
    const auto [q1, q2] =
        agent.q_values(agent.critic_features(conv, vectors, false), actions, false);
    const torch::Tensor loss = torch::mse_loss(q1, target) + torch::mse_loss(q2, target);
    critic_loss = k == 0 ? loss : critic_loss + loss;
    q_sum += q1.mean().item<double>();
  }
  UpdateStats stats;
  stats.critic_loss = critic_loss.item<double>();
  stats.q_mean = q_sum / static_cast<double>(copies);
  stats.target_mean = target.mean().item<double>();
  stats.alpha = alpha.item<double>();
  stats.actor_loss = std::numeric_limits<double>::quiet_NaN();
  stats.entropy = std::numeric_limits<double>::quiet_NaN();
  trainer::step_on_loss(critic_loss, stats.critic_loss, "drq: the critic loss",
                        {critic_optimizer_.get()}, ", Q mean " + std::to_string(stats.q_mean));

  // The actor and the temperature, on the first copy's encoder output (which the actor does not
  // train; it is the one from before the critic's step, as DrQ-v2 reuses it).
  if (updates_ % config_.actor_update_every == 0) {
    const torch::Tensor conv = first_conv.defined() ? first_conv.detach() : torch::Tensor();
    const PolicySample policy = agent.sample(agent.actor_features(conv, vectors), sampling);
    torch::Tensor critic_input;
    {
      // The critic's head is not trained by the actor: its output is a constant here.
      torch::NoGradGuard no_grad;
      critic_input = agent.critic_features(conv, vectors, false);
    }
    const auto [actor_q1, actor_q2] = agent.q_values(critic_input, policy.action, false);
    const torch::Tensor actor_loss =
        (alpha * policy.log_prob - torch::min(actor_q1, actor_q2)).mean();
    stats.actor_loss = actor_loss.item<double>();
    trainer::step_on_loss(actor_loss, stats.actor_loss, "drq: the actor loss",
                          {actor_optimizer_.get()});
    const torch::Tensor log_prob = policy.log_prob.detach();
    stats.entropy = -log_prob.mean().item<double>();
    const torch::Tensor alpha_loss = (agent.log_alpha.exp() * (-log_prob - target_entropy_)).mean();
    alpha_optimizer_->zero_grad();
    alpha_loss.backward();
    alpha_optimizer_->step();
  }
  if (updates_ % config_.target_update_every == 0) {
    if (agent.critic_head) soft_update(*agent.critic_head, *agent.target_head, config_.critic_tau);
    soft_update(*agent.q1, *agent.target_q1, config_.critic_tau);
    soft_update(*agent.q2, *agent.target_q2, config_.critic_tau);
  }
  ++updates_;
  return stats;
}

}  // namespace pixelgym::drq
