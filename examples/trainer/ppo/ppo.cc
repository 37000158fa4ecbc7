#include "examples/trainer/ppo/ppo.h"

#include <ATen/CPUGeneratorImpl.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <utility>

#include "examples/trainer/ppo/gae.h"
#include "examples/trainer/torch_common/torch_state.h"
#include "pixelgym/trainer/config_members.h"

namespace pixelgym::ppo {
namespace {

using Clock = std::chrono::steady_clock;

// vector::NormalizeReward's default epsilon: rewards are divided by sqrt(var + epsilon).
constexpr double kRewardEpsilon = 1e-8;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The steps after which a rollout may be preempted: ceil(fraction * num_steps), at least 1.
std::int64_t preempt_min_steps(std::int64_t num_steps, double fraction) {
  return std::max<std::int64_t>(
      1, static_cast<std::int64_t>(std::ceil(fraction * static_cast<double>(num_steps) - 1e-9)));
}

}  // namespace

// ---- PpoConfig -------------------------------------------------------------------------------

void PpoConfig::validate() const {
  trainer::check_settings(*this, "PpoConfig");
  auto fail = [](const std::string& what) { throw std::invalid_argument("PpoConfig: " + what); };
  if (num_minibatches > 0 && (num_steps * num_envs) % num_minibatches != 0) {
    fail("num_steps * num_envs (" + std::to_string(num_steps * num_envs) +
         ") must be a multiple of num_minibatches (" + std::to_string(num_minibatches) + ")");
  }
  if (preempt_stragglers && num_minibatches > 0 &&
      preempt_min_steps(num_steps, preempt_min_steps_fraction) * num_envs < num_minibatches) {
    fail("a rollout preempted after preempt_min_steps_fraction (" +
         std::to_string(preempt_min_steps_fraction) + ") of num_steps has " +
         std::to_string(preempt_min_steps(num_steps, preempt_min_steps_fraction) * num_envs) +
         " transitions, fewer than num_minibatches (" + std::to_string(num_minibatches) + ")");
  }
}

void to_json(nlohmann::json& json, const PolicyConfig& config) {
  trainer::write_settings(json, config);
}

void from_json(const nlohmann::json& json, PolicyConfig& config) {
  trainer::read_settings(json, config, "PolicyConfig");
  config.validate();
}

void to_json(nlohmann::json& json, const PpoConfig& config) {
  trainer::write_settings(json, config);
}

void from_json(const nlohmann::json& json, PpoConfig& config) {
  trainer::read_settings(json, config, "PpoConfig");
  config.validate();
}

std::string config_to_json(const PpoConfig& config) { return nlohmann::json(config).dump(2); }

PpoConfig config_from_json(const std::string& text) {
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& error) {
    throw std::invalid_argument(std::string("PpoConfig JSON: ") + error.what());
  }
  PpoConfig config;
  from_json(json, config);
  return config;
}

// ---- RolloutStorage --------------------------------------------------------------------------

RolloutStorage::RolloutStorage(const Policy& policy, std::int64_t steps, std::int64_t envs)
    : num_steps(steps), num_envs(envs) {
  for (const PolicyInput& input : policy.inputs()) {
    std::vector<std::int64_t> shape{steps, envs};
    shape.insert(shape.end(), input.shape.begin(), input.shape.end());
    observations.emplace(input.key, torch::zeros(shape, torch_dtype(input.dtype)));
  }
  if (policy.discrete()) {
    actions = torch::zeros({steps, envs}, torch::kInt64);
  } else {
    std::vector<std::int64_t> shape{steps, envs};
    shape.insert(shape.end(), policy.action_shape().begin(), policy.action_shape().end());
    actions = torch::zeros(shape, torch::kFloat32);
  }
  log_probs = torch::zeros({steps, envs});
  values = torch::zeros({steps, envs});
  rewards = torch::zeros({steps, envs});
  terminated = torch::zeros({steps, envs}, torch::kUInt8);
  truncated = torch::zeros({steps, envs}, torch::kUInt8);
  final_values = torch::zeros({steps, envs});
  last_values = torch::zeros({envs});
  advantages = torch::zeros({steps, envs});
  returns = torch::zeros({steps, envs});
}

void RolloutStorage::insert_observations(std::int64_t t, const ObservationTensors& obs) {
  for (auto& [key, stored] : observations) {
    auto found = obs.find(key);
    if (found == obs.end()) {
      throw std::invalid_argument("RolloutStorage: the observation batch has no key \"" + key +
                                  "\"");
    }
    stored[t].copy_(found->second);
  }
}

void RolloutStorage::compute_advantages(double gamma, double lambda, std::int64_t steps) {
  if (steps < 0) steps = num_steps;
  const torch::Tensor r = rewards.contiguous();
  const torch::Tensor v = values.contiguous();
  const torch::Tensor term = terminated.contiguous();
  const torch::Tensor trunc = truncated.contiguous();
  const torch::Tensor fv = final_values.contiguous();
  const torch::Tensor lv = last_values.contiguous();
  GaeInputs in;
  in.num_steps = steps;
  in.num_envs = num_envs;
  in.rewards = r.data_ptr<float>();
  in.values = v.data_ptr<float>();
  in.terminated = term.data_ptr<std::uint8_t>();
  in.truncated = trunc.data_ptr<std::uint8_t>();
  in.final_values = fv.data_ptr<float>();
  in.last_values = lv.data_ptr<float>();
  const GaeOutputs out = compute_gae(in, gamma, lambda);
  std::memcpy(advantages.data_ptr<float>(), out.advantages.data(),
              out.advantages.size() * sizeof(float));
  std::memcpy(returns.data_ptr<float>(), out.returns.data(), out.returns.size() * sizeof(float));
}

ObservationTensors RolloutStorage::flat_observations(std::int64_t steps) const {
  if (steps < 0) steps = num_steps;
  ObservationTensors flat;
  for (const auto& [key, stored] : observations) {
    flat.emplace(key, stored.slice(0, 0, steps).flatten(0, 1));
  }
  return flat;
}

// ---- Trainer ---------------------------------------------------------------------------------

namespace {

// The stats key of the trainer's own RecordEpisodeStatistics (not "episode": the env given may
// record its own).
const char* const kEpisodeKey = "ppo_episode";

// Rank r's generators are seeded seed + r * this (and + 1): far from the seeds of other ranks.
constexpr std::uint64_t kRankSeedStride = 1'000'003;

std::shared_ptr<Policy> make_policy(const vector::VectorEnv& env, const PpoConfig& config) {
  config.validate();
  trainer::require_memory(
      "ppo", memory_estimate(env.single_observation_space(), env.single_action_space(), config));
  if (env.autoreset_mode() != vector::AutoresetMode::kSameStep) {
    throw std::invalid_argument(
        std::string("Trainer: the vector env must autoreset in SameStep mode (truncated steps "
                    "bootstrap from infos[\"final_obs\"]), got ") +
        vector::autoreset_mode_name(env.autoreset_mode()));
  }
  if (env.num_envs() != config.num_envs) {
    throw std::invalid_argument("Trainer: config.num_envs is " + std::to_string(config.num_envs) +
                                " but the vector env has " + std::to_string(env.num_envs()));
  }
  torch::manual_seed(config.seed);
  return std::make_shared<Policy>(env.single_observation_space(), env.single_action_space(),
                                  config.policy);
}

}  // namespace

std::vector<trainer::MemoryUse> memory_estimate(const Space& observation_space,
                                                const Space& action_space,
                                                const PpoConfig& config) {
  const auto d = [](std::int64_t value) { return static_cast<double>(value); };
  constexpr double kFloat = 4.0;
  double observation_bytes = 0;
  double observation_elements = 0;
  double image_elements = 0;  // uint8 keys: the CNNs' inputs
  for (const Array& array : observation_space.zeros().leaves()) {
    observation_bytes += static_cast<double>(array.nbytes());
    observation_elements += static_cast<double>(array.size());
    if (array.dtype() == DType::kUInt8) image_elements += static_cast<double>(array.size());
  }
  double action_elements = 0;
  for (const Array& array : action_space.zeros().leaves()) {
    action_elements += static_cast<double>(array.size());
  }
  const PolicyConfig& policy = config.policy;
  // Per stored step of one env: its observation, action (int64 or float32) and the ten per-step
  // figures; per sample of a minibatch: the float observation (twice with augmentation) and the
  // activations kept for backward, about six times the input.
  const double per_step = observation_bytes + 8 * action_elements + 10 * kFloat;
  const double minibatch = d(config.num_steps) * d(config.num_envs) / d(config.num_minibatches);
  const double per_sample = kFloat * 8 * observation_elements;
  // The widths: the CNN's closing layer reads at most a quarter of the input's elements (a
  // stride of 2 or more, 32 or fewer channels), the trunk the fused features; trained weights are
  // kept four times (weights, gradients, Adam's two moments), twice with a value network.
  double mlp = 0;
  double widest = 0;
  double previous = observation_elements - image_elements;
  for (const std::int64_t width : policy.mlp_hidden) {
    mlp += previous * d(width);
    previous = d(width);
    widest = std::max(widest, d(width));
  }
  const double fused = (image_elements > 0 ? d(policy.cnn_features) : 0) + previous;
  const double copies = kFloat * 4 * (policy.separate_value_network ? 2 : 1);
  return {
      {"num_steps", d(config.num_steps),
       "the rollout of " + std::to_string(config.num_envs) +
           " envs and the activations of a minibatch",
       d(config.num_steps) * d(config.num_envs) * per_step + minibatch * per_sample},
      {"policy.cnn_features", d(policy.cnn_features), "the CNN's closing layer",
       copies * d(policy.cnn_features) * image_elements / 4},
      {"policy.mlp_hidden", widest, "the MLP over the vector keys", copies * mlp},
      {"policy.trunk_hidden", d(policy.trunk_hidden), "the trunk and heads",
       copies * d(policy.trunk_hidden) * (fused + action_elements + 1)},
  };
}

Trainer::Trainer(vector::VectorEnv& env, PpoConfig config)
    : Trainer(env, nullptr, std::move(config), single_process_) {}

Trainer::Trainer(vector::VectorEnv& env, PpoConfig config, trainer::Communicator& communicator)
    : Trainer(env, nullptr, std::move(config), communicator) {}

Trainer::Trainer(trainer::EnvLoop& loop, PpoConfig config, trainer::Communicator& communicator)
    : Trainer(loop.env(), &loop, std::move(config), communicator) {}

Trainer::Trainer(vector::VectorEnv& env, trainer::EnvLoop* loop, PpoConfig config,
                 trainer::Communicator& communicator)
    : config_(std::move(config)),
      policy_(make_policy(env, config_)),
      reward_scaling_(static_cast<std::size_t>(config_.num_envs), config_.gamma, kRewardEpsilon,
                      "Trainer"),
      scaled_rewards_(static_cast<std::size_t>(config_.num_envs)),
      ended_(static_cast<std::size_t>(config_.num_envs)),
      optimizer_(std::make_unique<torch::optim::Adam>(
          policy_->parameters(),
          torch::optim::AdamOptions(config_.learning_rate).eps(config_.adam_epsilon))),
      storage_(*policy_, config_.num_steps, config_.num_envs),
      sampling_(at::detail::createCPUGenerator(config_.seed)),
      augmentation_(at::detail::createCPUGenerator(config_.seed + 1)),
      actions_(env.action_space().zeros()) {
  if (!actions_.is_array()) {
    throw std::invalid_argument("Trainer: the batched action space must be an array space, got " +
                                env.action_space().to_string());
  }
  communicator_ = &communicator;
  if (loop == nullptr) {
    own_loop_ = std::make_unique<trainer::EnvLoop>(env, env_seed(), kEpisodeKey);
    loop = own_loop_.get();
  } else if (loop->seed() != env_seed()) {
    throw std::invalid_argument("Trainer: the env loop resets its envs with seed " +
                                std::to_string(loop->seed()) + ", but rank " +
                                std::to_string(communicator_->rank()) + "'s env seed is " +
                                std::to_string(env_seed()) + " (config.seed + rank num_envs)");
  }
  loop_ = loop;
  reward_statistics_before_ = reward_scaling_.statistics();
  if (alone()) return;
  const auto rank = static_cast<std::uint64_t>(communicator_->rank());
  sampling_ = at::detail::createCPUGenerator(config_.seed + rank * kRankSeedStride);
  augmentation_ = at::detail::createCPUGenerator(config_.seed + 1 + rank * kRankSeedStride);
  // Every rank built the same weights from the same seed, but a library on another machine may
  // round differently: rank 0's are everyone's, and the digests must then agree.
  torch::NoGradGuard no_grad;
  for (torch::Tensor& parameter : policy_->parameters()) {
    torch::Tensor flat = parameter.detach().contiguous();
    communicator_->broadcast(flat.data_ptr<float>(), static_cast<std::size_t>(flat.numel()),
                             "the initial parameters' broadcast");
    parameter.copy_(flat);
  }
  trainer::check_same_on_every_rank(*communicator_, parameter_digest(), 0);
}

std::uint64_t Trainer::env_seed() const {
  const auto rank = static_cast<std::uint64_t>(communicator_->rank());
  return config_.seed + rank * static_cast<std::uint64_t>(config_.num_envs);
}

std::uint64_t Trainer::parameter_digest() const { return trainer::parameter_digest(*policy_); }

void Trainer::all_reduce(std::vector<double>& values, const std::string& what) {
  if (alone()) return;
  const auto start = Clock::now();
  communicator_->all_reduce_sum(values.data(), values.size(), what);
  collective_seconds_ += seconds_since(start);
}

void Trainer::average_gradients(const MinibatchPosition& at) {
  if (alone()) return;
  std::vector<torch::Tensor> gradients;
  for (const torch::Tensor& parameter : policy_->parameters()) {
    if (parameter.grad().defined()) gradients.push_back(parameter.grad());
  }
  if (gradients.empty()) return;
  std::vector<torch::Tensor> flat;
  flat.reserve(gradients.size());
  for (const torch::Tensor& gradient : gradients) flat.push_back(gradient.reshape({-1}));
  torch::Tensor buffer = torch::cat(flat).contiguous();
  const auto start = Clock::now();
  communicator_->all_reduce_sum(
      buffer.data_ptr<float>(), static_cast<std::size_t>(buffer.numel()),
      "the gradient all-reduce of update " + std::to_string(updates_ + 1) + ", epoch " +
          std::to_string(at.epoch + 1) + ", minibatch " + std::to_string(at.minibatch + 1));
  collective_seconds_ += seconds_since(start);
  buffer.div_(static_cast<double>(communicator_->world_size()));
  std::int64_t offset = 0;
  for (torch::Tensor& gradient : gradients) {
    const std::int64_t size = gradient.numel();
    gradient.copy_(buffer.slice(0, offset, offset + size).view_as(gradient));
    offset += size;
  }
}

void Trainer::merge_statistics(
    const std::map<std::string, wrappers::RunningStatistics>& observations,
    const wrappers::RunningStatistics& rewards) {
  if (alone()) return;
  for (const auto& [key, before] : observations) {
    wrappers::RunningStatistics merged = policy_->observation_statistics(key);
    trainer::merge_statistics_across_ranks(*communicator_, before, merged,
                                           "the observation statistics of \"" + key + "\"");
    policy_->set_observation_statistics(key, merged);
  }
  if (!config_.normalize_rewards) return;
  wrappers::RunningStatistics merged = reward_scaling_.statistics();
  trainer::merge_statistics_across_ranks(*communicator_, rewards, merged,
                                         "the reward scaling's statistics");
  reward_scaling_.set_statistics(merged);
  reward_statistics_before_ = std::move(merged);
}

bool Trainer::preempted(std::int64_t steps_done) {
  if (!config_.preempt_stragglers || alone() || steps_done >= config_.num_steps ||
      steps_done < preempt_min_steps(config_.num_steps, config_.preempt_min_steps_fraction)) {
    return false;
  }
  const auto needed = static_cast<int>(
      std::ceil(config_.preempt_done_fraction * communicator_->world_size() - 1e-9));
  return communicator_->rollouts_done(updates_) >= std::max(needed, 1);
}

void Trainer::replay_env(const std::string& env_action_log) {
  if (loop_->started()) {
    throw std::logic_error("Trainer::replay_env: the envs were already reset or stepped");
  }
  // Distributed, a rank's own steps are not env_steps_ (every rank's), nor its share when
  // stragglers were preempted: its log holds whole batches.
  const std::int64_t steps =
      alone() ? env_steps_
              : static_cast<std::int64_t>(env_action_log.size() / loop_->batch_bytes()) *
                    config_.num_envs;
  // No policy and no reward statistics: those come from the checkpoint.
  loop_->replay(
      env_action_log, steps, [](const Value& /*first*/) {},
      [](const Value& /*actions*/, const vector::VectorStepResult& /*step*/) {});
  log_from_start_ = true;
}

bool Trainer::env_action_log_complete() const {
  if (!alone()) return log_from_start_;
  return loop_->action_log_covers(env_steps_);
}

std::uint64_t Trainer::env_digest() const { return loop_->digest(); }

bool Trainer::alone() const { return communicator_->world_size() == 1; }

RolloutStats Trainer::collect(const trainer::StopCheck& stop) {
  torch::NoGradGuard no_grad;
  RolloutStats stats;
  if (!loop_->started()) {
    const auto start = Clock::now();
    loop_->reset();
    if (config_.normalize_rewards) reward_scaling_.reset();
    stats.env_seconds += seconds_since(start);
  }
  // Views of the loop's observation batch (also after a replay of the loop's actions).
  current_obs_ = observation_tensors(loop_->observations());
  Array& env_actions = actions_.array();
  const std::int64_t envs = config_.num_envs;
  std::int64_t steps = 0;
  for (std::int64_t t = 0; t < config_.num_steps && !preempted(t); ++t) {
    steps = t + 1;
    auto start = Clock::now();
    const ActResult act = policy_->act(current_obs_, /*deterministic=*/false, sampling_);
    stats.policy_seconds += seconds_since(start);
    storage_.insert_observations(t, current_obs_);
    storage_.actions[t].copy_(act.action);
    storage_.log_probs[t].copy_(act.log_prob);
    storage_.values[t].copy_(act.value);
    const torch::Tensor env_action =
        act.env_action.to(torch_dtype(env_actions.dtype())).contiguous();
    if (static_cast<std::size_t>(env_action.nbytes()) != env_actions.nbytes()) {
      throw std::logic_error("Trainer: the policy's actions do not match the action batch " +
                             env_actions.to_string());
    }
    std::memcpy(env_actions.raw_data(), env_action.data_ptr(), env_actions.nbytes());

    start = Clock::now();
    const vector::VectorStepResult& step = loop_->step(actions_);
    stats.env_seconds += seconds_since(start);
    const double* rewards = step.rewards.data<double>();
    const bool* terminated = step.terminated.data<bool>();
    const bool* truncated = step.truncated.data<bool>();
    if (config_.normalize_rewards) {
      for (std::int64_t n = 0; n < envs; ++n) {
        ended_[static_cast<std::size_t>(n)] = terminated[n] || truncated[n] ? 1 : 0;
      }
      reward_scaling_.scale(rewards, ended_.data(), nullptr, scaled_rewards_.data());
      rewards = scaled_rewards_.data();
    }
    for (const trainer::EndedEpisode& episode : loop_->ended_episodes(step)) {
      stats.episodes.push_back({episode.episode_return, episode.length});
    }
    // The storage tensors are contiguous (T, N): row t starts at t * N.
    float* stored_rewards = storage_.rewards.data_ptr<float>() + t * envs;
    std::uint8_t* stored_terminated = storage_.terminated.data_ptr<std::uint8_t>() + t * envs;
    std::uint8_t* stored_truncated = storage_.truncated.data_ptr<std::uint8_t>() + t * envs;
    float* stored_final_values = storage_.final_values.data_ptr<float>() + t * envs;
    std::vector<std::int64_t> bootstrap;  // envs truncated (not terminated) in this step
    for (std::int64_t n = 0; n < envs; ++n) {
      stored_rewards[n] = static_cast<float>(rewards[n]);
      stored_terminated[n] = terminated[n] ? 1 : 0;
      stored_truncated[n] = truncated[n] ? 1 : 0;
      stored_final_values[n] = 0.0f;
      if (truncated[n] && !terminated[n]) bootstrap.push_back(n);
    }
    if (!bootstrap.empty()) {
      if (!step.infos.contains("final_obs")) {
        throw std::logic_error("Trainer: a truncated step without infos[\"final_obs\"]");
      }
      start = Clock::now();
      const torch::Tensor rows = torch::tensor(bootstrap, torch::kInt64);
      const ObservationTensors final_obs =
          select_rows(observation_tensors(step.infos.at("final_obs")), rows);
      storage_.final_values[t].index_copy_(0, rows, policy_->value(final_obs));
      stats.policy_seconds += seconds_since(start);
    }
    current_obs_ = observation_tensors(step.obs);
    // Every minibatch of the update must hold a transition.
    if (stop && stop(env_steps_ + steps * envs) && alone() &&
        steps * envs >= config_.num_minibatches) {
      break;
    }
  }
  const auto start = Clock::now();
  storage_.last_values.copy_(policy_->value(current_obs_));
  stats.policy_seconds += seconds_since(start);
  storage_.compute_advantages(config_.gamma, config_.gae_lambda, steps);
  collected_steps_ = steps;
  std::vector<double> rollout_steps{static_cast<double>(steps * envs)};
  if (config_.preempt_stragglers) {
    communicator_->mark_rollout_done(updates_);
  }
  all_reduce(rollout_steps, "the rollout's step count");
  last_rollout_steps_ = static_cast<std::int64_t>(std::llround(rollout_steps[0]));
  env_steps_ += last_rollout_steps_;
  collected_ = true;
  return stats;
}

double Trainer::learning_rate() const {
  if (!config_.anneal_learning_rate) return config_.learning_rate;
  // The steps done before the rollout being learned from: the first update uses the full rate.
  const std::int64_t before = collected_ ? env_steps_ - last_rollout_steps_ : env_steps_;
  const double remaining =
      1.0 - static_cast<double>(before) / static_cast<double>(config_.total_env_steps);
  return config_.learning_rate * std::max(remaining, 0.0);
}

Trainer::UpdateBatch Trainer::update_batch() {
  UpdateBatch batch;
  const std::int64_t steps = collected_steps_;
  batch.size = steps * config_.num_envs;
  batch.minibatch = batch.size / config_.num_minibatches;
  batch.obs = storage_.flat_observations(steps);
  batch.actions = storage_.actions.slice(0, 0, steps).flatten(0, 1);
  batch.old_log_probs = storage_.log_probs.slice(0, 0, steps).flatten(0, 1);
  batch.old_values = storage_.values.slice(0, 0, steps).flatten(0, 1);
  batch.advantages = storage_.advantages.slice(0, 0, steps).flatten(0, 1);
  batch.returns = storage_.returns.slice(0, 0, steps).flatten(0, 1);
  if (!config_.augment) return batch;
  batch.shifts =
      torch::randint(0, 2 * config_.shift_pad + 1, {batch.size, 2}, augmentation_, torch::kInt64);
  // Old log-probs and values of the shifted images, so that the ratio starts at 1.
  torch::NoGradGuard no_grad;
  batch.old_log_probs = torch::empty_like(batch.old_log_probs);
  batch.old_values = torch::empty_like(batch.old_values);
  for (std::int64_t begin = 0; begin < batch.size; begin += batch.minibatch) {
    const torch::Tensor index =
        torch::arange(begin, std::min(begin + batch.minibatch, batch.size), torch::kInt64);
    const Evaluation old =
        policy_->evaluate(select_rows(batch.obs, index), batch.actions.index_select(0, index),
                          batch.shifts.index_select(0, index), config_.shift_pad);
    batch.old_log_probs.index_copy_(0, index, old.log_prob);
    batch.old_values.index_copy_(0, index, old.value);
  }
  return batch;
}

torch::Tensor Trainer::value_loss(const UpdateBatch& batch, const torch::Tensor& index,
                                  const torch::Tensor& value) const {
  const torch::Tensor target = batch.returns.index_select(0, index);
  if (!config_.clip_value_loss) return 0.5 * (value - target).pow(2).mean();
  const torch::Tensor old = batch.old_values.index_select(0, index);
  const torch::Tensor clipped = old + (value - old).clamp(-config_.clip_range, config_.clip_range);
  return 0.5 * torch::max((value - target).pow(2), (clipped - target).pow(2)).mean();
}

double Trainer::step_optimizer(const torch::Tensor& loss, double checked_loss,
                               const std::string& losses, const MinibatchPosition& at) {
  loss.backward();
  average_gradients(at);
  const double grad_norm =
      torch::nn::utils::clip_grad_norm_(policy_->parameters(), config_.max_grad_norm);
  if (!std::isfinite(checked_loss) || !std::isfinite(grad_norm)) {
    // A step would write NaN or infinite weights; the next rollout would then act with NaN.
    throw std::runtime_error("Trainer::update: update " + std::to_string(updates_ + 1) +
                             ", epoch " + std::to_string(at.epoch + 1) + ", minibatch " +
                             std::to_string(at.minibatch + 1) + " diverged: " + losses +
                             ", gradient norm " + std::to_string(grad_norm) +
                             "; the parameters are left as the previous minibatch made them, not "
                             "stepped");
  }
  optimizer_->step();
  return grad_norm;
}

void Trainer::step_value_only(const UpdateBatch& batch, const torch::Tensor& index,
                              const MinibatchPosition& at) {
  const Evaluation now = policy_->evaluate(
      select_rows(batch.obs, index), batch.actions.index_select(0, index),
      batch.shifts.defined() ? batch.shifts.index_select(0, index) : torch::Tensor(),
      config_.shift_pad);
  const torch::Tensor loss = value_loss(batch, index, now.value);
  // Gradients left undefined are skipped by Adam (a zero gradient would still move the policy's
  // parameters through Adam's momentum).
  for (const torch::Tensor& parameter : policy_->parameters()) parameter.mutable_grad().reset();
  const double checked = loss.item<double>();
  step_optimizer(config_.value_coef * loss, checked, "value loss " + std::to_string(checked), at);
}

double Trainer::step_minibatch(const UpdateBatch& batch, const torch::Tensor& index,
                               const MinibatchPosition& at, UpdateStats& stats) {
  const Evaluation now = policy_->evaluate(
      select_rows(batch.obs, index), batch.actions.index_select(0, index),
      batch.shifts.defined() ? batch.shifts.index_select(0, index) : torch::Tensor(),
      config_.shift_pad);
  const torch::Tensor value = value_loss(batch, index, now.value);
  const torch::Tensor log_ratio = now.log_prob - batch.old_log_probs.index_select(0, index);
  const torch::Tensor ratio = log_ratio.exp();
  torch::Tensor advantage = batch.advantages.index_select(0, index);
  if (config_.normalize_advantages) {
    if (alone()) {
      if (advantage.size(0) > 1) {
        advantage = (advantage - advantage.mean()) / (advantage.std() + 1e-8);
      }
    } else {
      // The mean and (unbiased) standard deviation of every rank's minibatch together.
      const torch::Tensor wide = advantage.to(torch::kFloat64);
      std::vector<double> moments{static_cast<double>(advantage.size(0)), wide.sum().item<double>(),
                                  wide.pow(2).sum().item<double>()};
      all_reduce(moments, "the advantages' moments");
      if (moments[0] > 1.0) {
        const double mean = moments[1] / moments[0];
        const double var =
            std::max(moments[2] - moments[0] * mean * mean, 0.0) / (moments[0] - 1.0);
        advantage = (advantage - mean) / (std::sqrt(var) + 1e-8);
      }
    }
  }
  const torch::Tensor policy_loss =
      torch::max(-advantage * ratio,
                 -advantage * ratio.clamp(1.0 - config_.clip_range, 1.0 + config_.clip_range))
          .mean();
  const torch::Tensor entropy = now.entropy.mean();
  const torch::Tensor loss =
      policy_loss - config_.entropy_coef * entropy + config_.value_coef * value;

  optimizer_->zero_grad();
  const double grad_norm =
      step_optimizer(loss, loss.item<double>(),
                     "loss " + std::to_string(loss.item<double>()) + " (policy " +
                         std::to_string(policy_loss.item<double>()) + ", value " +
                         std::to_string(value.item<double>()) + ")",
                     at);
  double approx_kl;
  {
    torch::NoGradGuard no_grad;
    approx_kl = ((ratio - 1.0) - log_ratio).mean().item<double>();
    stats.clip_fraction +=
        ((ratio - 1.0).abs() > config_.clip_range).to(torch::kFloat32).mean().item<double>();
  }
  stats.policy_loss += policy_loss.item<double>();
  stats.value_loss += value.item<double>();
  stats.entropy += entropy.item<double>();
  stats.approx_kl += approx_kl;
  stats.grad_norm += grad_norm;
  stats.minibatches += 1;
  return approx_kl;
}

UpdateStats Trainer::update(const trainer::StopCheck& stop_check) {
  if (!collected_) throw std::logic_error("Trainer::update: no rollout collected since the last");
  UpdateStats stats;
  collective_seconds_ = 0.0;
  stats.learning_rate = learning_rate();
  for (auto& group : optimizer_->param_groups()) {
    static_cast<torch::optim::AdamOptions&>(group.options()).lr(stats.learning_rate);
  }
  const UpdateBatch batch = update_batch();
  // With a separate value network the KL stop ends only the policy's steps: the value's loss
  // reaches none of the policy's parameters, so the value network can go on through every epoch
  // without moving the policy.
  const bool value_after_stop = policy_->config().separate_value_network;
  bool stop = false;
  bool out_of_time = false;
  for (std::int64_t epoch = 0;
       epoch < config_.update_epochs && !(stop && !value_after_stop) && !out_of_time; ++epoch) {
    const torch::Tensor order = minibatch_order_
                                    ? minibatch_order_(epoch, batch.size)
                                    : torch::randperm(batch.size, sampling_, torch::kInt64);
    if (order.dim() != 1 || order.size(0) != batch.size) {
      throw std::invalid_argument("Trainer::update: the minibatch order of epoch " +
                                  std::to_string(epoch) + " must be a permutation of " +
                                  std::to_string(batch.size) + " indices");
    }
    std::int64_t policy_steps_in_epoch = 0;
    for (std::int64_t m = 0; m < config_.num_minibatches; ++m) {
      // Near-equal slices when a preempted rollout is not a multiple of num_minibatches.
      const torch::Tensor index = order.slice(0, m * batch.size / config_.num_minibatches,
                                              (m + 1) * batch.size / config_.num_minibatches);
      const MinibatchPosition at{epoch, m};
      // Out of time (the run's check, asked after every minibatch, alone only: the ranks' updates
      // must take the same minibatches).
      const auto out_of_time_now = [&] { return stop_check && stop_check(env_steps_) && alone(); };
      if (stop) {
        step_value_only(batch, index, at);
        stats.value_minibatches += 1;
        if (out_of_time_now()) {
          out_of_time = true;
          break;
        }
        continue;
      }
      double approx_kl = step_minibatch(batch, index, at, stats);
      policy_steps_in_epoch += 1;
      if (config_.target_kl > 0.0 && !alone()) {
        // Every rank must stop at the same minibatch: the mean KL over the ranks decides.
        std::vector<double> kl{approx_kl};
        all_reduce(kl, "the approximate KL");
        approx_kl = kl[0] / communicator_->world_size();
      }
      if (config_.target_kl > 0.0 && approx_kl > config_.target_kl) {
        stop = true;
        if (!value_after_stop) break;
      }
      if (out_of_time_now()) {
        out_of_time = true;
        break;
      }
    }
    if (policy_steps_in_epoch > 0) stats.epochs += 1;
  }
  finish_update_stats(stats);
  std::map<std::string, wrappers::RunningStatistics> observations_before;
  if (!alone() && policy_->config().normalize_observations) {
    for (const PolicyInput& input : policy_->inputs()) {
      try {
        observations_before.emplace(input.key, policy_->observation_statistics(input.key));
      } catch (const std::out_of_range&) {
        // An image key: not normalized.
      }
    }
  }
  policy_->update_observation_statistics(batch.obs);
  merge_statistics(observations_before, reward_statistics_before_);
  stats.allreduce_seconds = collective_seconds_;
  updates_ += 1;
  collected_ = false;
  return stats;
}

void Trainer::finish_update_stats(UpdateStats& stats) {
  const auto count = static_cast<double>(stats.minibatches);
  stats.policy_loss /= count;
  stats.value_loss /= count;
  stats.entropy /= count;
  stats.approx_kl /= count;
  stats.clip_fraction /= count;
  stats.grad_norm /= count;
  const torch::Tensor values = storage_.values.slice(0, 0, collected_steps_).flatten();
  const torch::Tensor targets =
      storage_.returns.slice(0, 0, collected_steps_).flatten().to(torch::kFloat64);
  const torch::Tensor errors = targets - values.to(torch::kFloat64);
  // Sums, so that a distributed update reports the figures of every rank's transitions.
  std::vector<double> sums{stats.policy_loss,
                           stats.value_loss,
                           stats.entropy,
                           stats.approx_kl,
                           stats.clip_fraction,
                           static_cast<double>(targets.numel()),
                           targets.sum().item<double>(),
                           targets.pow(2).sum().item<double>(),
                           errors.sum().item<double>(),
                           errors.pow(2).sum().item<double>()};
  all_reduce(sums, "the update's statistics");
  const double ranks = communicator_->world_size();
  stats.policy_loss = sums[0] / ranks;
  stats.value_loss = sums[1] / ranks;
  stats.entropy = sums[2] / ranks;
  stats.approx_kl = sums[3] / ranks;
  stats.clip_fraction = sums[4] / ranks;
  const double n = sums[5];
  const double variance = sums[7] / n - (sums[6] / n) * (sums[6] / n);
  const double error_variance = sums[9] / n - (sums[8] / n) * (sums[8] / n);
  stats.explained_variance = variance <= 0.0 ? 0.0 : 1.0 - error_variance / variance;
}

void Trainer::set_progress(std::int64_t env_steps, std::int64_t updates) {
  if (env_steps < 0 || updates < 0) {
    throw std::invalid_argument("Trainer::set_progress: counts must be >= 0");
  }
  env_steps_ = env_steps;
  updates_ = updates;
  log_from_start_ = env_steps == 0 && loop_->action_log().empty();
}

void Trainer::load_rollout(const RolloutStorage& rollout) {
  if (rollout.num_steps != config_.num_steps || rollout.num_envs != config_.num_envs) {
    throw std::invalid_argument(
        "Trainer::load_rollout: a rollout of " + std::to_string(config_.num_steps) + " x " +
        std::to_string(config_.num_envs) + " expected, got " + std::to_string(rollout.num_steps) +
        " x " + std::to_string(rollout.num_envs));
  }
  for (auto& [key, stored] : storage_.observations) stored.copy_(rollout.observations.at(key));
  storage_.actions.copy_(rollout.actions);
  storage_.log_probs.copy_(rollout.log_probs);
  storage_.values.copy_(rollout.values);
  storage_.rewards.copy_(rollout.rewards);
  storage_.terminated.copy_(rollout.terminated);
  storage_.truncated.copy_(rollout.truncated);
  storage_.final_values.copy_(rollout.final_values);
  storage_.last_values.copy_(rollout.last_values);
  storage_.advantages.copy_(rollout.advantages);
  storage_.returns.copy_(rollout.returns);
  collected_steps_ = config_.num_steps;
  const std::int64_t ranks = communicator_->world_size();
  last_rollout_steps_ = config_.num_steps * config_.num_envs * ranks;
  env_steps_ += last_rollout_steps_;
  collected_ = true;
}

RewardScaling Trainer::reward_scaling() const {
  return {reward_scaling_.statistics(), reward_scaling_.discounted_returns()};
}

void Trainer::set_reward_scaling(RewardScaling scaling) {
  const std::string invalid = scaling.statistics.invalid_reason(1);
  if (!invalid.empty()) {
    throw std::invalid_argument("Trainer::set_reward_scaling: invalid statistics: " + invalid);
  }
  if (static_cast<std::int64_t>(scaling.returns.size()) != config_.num_envs) {
    throw std::invalid_argument("Trainer::set_reward_scaling: " + std::to_string(config_.num_envs) +
                                " discounted returns expected (num_envs), got " +
                                std::to_string(scaling.returns.size()));
  }
  for (const double r : scaling.returns) {
    if (!std::isfinite(r)) {
      throw std::invalid_argument("Trainer::set_reward_scaling: a discounted return is " +
                                  std::to_string(r));
    }
  }
  reward_statistics_before_ = scaling.statistics;
  reward_scaling_.set_statistics(std::move(scaling.statistics));
  reward_scaling_.set_discounted_returns(std::move(scaling.returns));
}

TrainerRngState Trainer::rng_state() const {
  return {sampling_.get_state(), augmentation_.get_state()};
}

void Trainer::set_rng_state(const TrainerRngState& state) {
  sampling_.set_state(state.sampling);
  augmentation_.set_state(state.augmentation);
}

}  // namespace pixelgym::ppo
