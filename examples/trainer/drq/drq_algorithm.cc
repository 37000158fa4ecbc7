#include "examples/trainer/drq/drq_algorithm.h"

#include <ATen/CPUGeneratorImpl.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "examples/trainer/torch_common/observation_tensors.h"
#include "examples/trainer/torch_common/off_policy_networks.h"
#include "examples/trainer/torch_common/torch_state.h"
#include "pixelgym/envs/vector/vector_wrapper.h"

namespace pixelgym::drq {

using trainer::ActCounts;
using trainer::CheckpointBlobs;
using trainer::IterationStats;
using trainer::LoadedCheckpoint;

namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The stats key of the learner's own RecordEpisodeStatistics (the env may record "episode").
const char* const kEpisodeKey = "drq_episode";

const DrqConfig& checked(const DrqConfig& config, const vector::VectorEnv& env) {
  config.validate();
  if (env.autoreset_mode() != vector::AutoresetMode::kSameStep) {
    throw std::invalid_argument(
        std::string("drq: the vector env must autoreset in SameStep mode (an episode's last "
                    "observation comes from infos[\"final_obs\"]), got ") +
        vector::autoreset_mode_name(env.autoreset_mode()));
  }
  if (env.num_envs() != config.num_envs) {
    throw std::invalid_argument("drq: config num_envs is " + std::to_string(config.num_envs) +
                                " but the vector env has " + std::to_string(env.num_envs()));
  }
  trainer::require_memory(
      "drq", trainer::off_policy_memory_estimate(
                 trainer::input_layout(env.single_observation_space(), env.single_action_space(),
                                       config.frame_stack, "drq", env.name()),
                 {config.replay_capacity, config.batch_size * config.augmented_copies,
                  config.hidden_dim, config.feature_dim, config.encoder}));
  return config;
}

// Row `row` of the batched observation `obs` as the buffer reads it.
ObservationView view_row(const std::map<std::string, torch::Tensor>& obs, const InputLayout& input,
                         std::int64_t row) {
  ObservationView view;
  if (input.has_image) {
    const torch::Tensor& images = obs.at(input.image_key);
    view.images.push_back(images.data_ptr<std::uint8_t>() + row * images.stride(0));
  }
  for (const std::string& key : input.vector_keys) {
    const torch::Tensor& values = obs.at(key);
    view.vectors.push_back(values.data_ptr<float>() + row * values.stride(0));
  }
  return view;
}

double mean_or_none(double sum, std::int64_t count) {
  return count > 0 ? sum / static_cast<double>(count) : trainer::ProgressRow::kNone;
}

}  // namespace

// ---- DrqActor ------------------------------------------------------------------------------

DrqActor::DrqActor(std::shared_ptr<Agent> agent, std::uint64_t seed)
    : agent_(std::move(agent)), sampling_(at::detail::createCPUGenerator(seed)) {
  if (!agent_) throw std::invalid_argument("DrqActor: the agent is null");
}

ActCounts DrqActor::act(const Value& observations, bool deterministic, Value& actions) {
  const torch::Tensor unit =
      agent_->act(trainer::observation_tensors(observations), deterministic, &sampling_);
  Array& action = actions.array();
  const torch::Tensor chosen =
      agent_->env_action(unit).to(trainer::torch_dtype(action.dtype())).contiguous();
  std::memcpy(action.raw_data(), chosen.data_ptr(), action.nbytes());
  // The tanh policy's actions lie within the bounds: none is clipped.
  return {0, unit.numel()};
}

// ---- DrqAlgorithm --------------------------------------------------------------------------

DrqAlgorithm::DrqAlgorithm(vector::VectorEnv& env, DrqConfig config)
    : config_(checked(config, env)),
      episodes_(std::make_unique<vector::VectorWrapper>(env), 1, kEpisodeKey),
      learner_(trainer::input_layout(env.single_observation_space(), env.single_action_space(),
                                     config_.frame_stack, "drq", env.name()),
               config_),
      buffer_(learner_.agent().input().replay_layout(), config_.num_envs, config_.replay_capacity,
              config_.n_step, config_.gamma),
      replay_rng_(config_.seed),
      augmentation_(at::detail::createCPUGenerator(config_.seed + 1)),
      exploration_(at::detail::createCPUGenerator(config_.seed + 2)),
      sampling_(at::detail::createCPUGenerator(config_.seed + 3)),
      actions_(env.action_space().zeros()),
      actor_(learner_.agent_ptr(), config_.seed + 4) {}

void DrqAlgorithm::start() {
  current_obs_ = trainer::observation_tensors(episodes_.reset(config_.seed).obs);
  for (std::int64_t e = 0; e < config_.num_envs; ++e) {
    buffer_.add_first(e, view_row(current_obs_, learner_.agent().input(), e));
  }
  started_ = true;
}

void DrqAlgorithm::choose_actions(StepTimes& times) {
  const auto start = Clock::now();
  Agent& agent = learner_.agent();
  torch::Tensor unit;
  if (env_steps_ < config_.seed_env_steps) {
    unit = torch::rand({config_.num_envs, agent.input().action_size}, exploration_) * 2.0 - 1.0;
  } else {
    unit = agent.act(current_obs_, false, &exploration_);
  }
  Array& action = actions_.array();
  const torch::Tensor chosen =
      agent.env_action(unit).to(trainer::torch_dtype(action.dtype())).contiguous();
  std::memcpy(action.raw_data(), chosen.data_ptr(), action.nbytes());
  env_action_log_.append(static_cast<const char*>(action.raw_data()), action.nbytes());
  times.act += seconds_since(start);
}

void DrqAlgorithm::step_env(std::vector<double>* ended_returns, StepTimes& times) {
  auto start = Clock::now();
  const vector::VectorStepResult& step = episodes_.step(actions_);
  times.env += seconds_since(start);
  const InputLayout& input = learner_.agent().input();
  // The buffer keeps actions in [-1, 1], as the actor gives them, from what the env was sent
  // (so that a replayed log fills the buffer with the same bytes).
  Array& action = actions_.array();
  const torch::Tensor unit =
      learner_.agent()
          .unit_action(trainer::array_tensor(action).reshape({config_.num_envs, -1}))
          .contiguous();
  const double* rewards = step.rewards.data<double>();
  const bool* terminated = step.terminated.data<bool>();
  const bool* truncated = step.truncated.data<bool>();
  current_obs_ = trainer::observation_tensors(step.obs);
  std::map<std::string, torch::Tensor> final_obs;
  const bool* ended_mask = nullptr;
  if (step.infos.contains("_" + std::string(kEpisodeKey))) {
    ended_mask = step.infos.at("_" + std::string(kEpisodeKey)).array().data<bool>();
  }
  for (std::int64_t e = 0; e < config_.num_envs; ++e) {
    const bool ended = terminated[e] || truncated[e];
    if (ended && final_obs.empty()) {
      if (!step.infos.contains("final_obs")) {
        throw std::logic_error("drq: an episode ended without infos[\"final_obs\"]");
      }
      final_obs = trainer::observation_tensors(step.infos.at("final_obs"));
    }
    buffer_.add_step(e, unit[e].data_ptr<float>(), rewards[e], terminated[e], truncated[e],
                     view_row(ended ? final_obs : current_obs_, input, e));
    if (ended) buffer_.add_first(e, view_row(current_obs_, input, e));
  }
  if (ended_returns != nullptr && ended_mask != nullptr) {
    const double* returns = step.infos.at(kEpisodeKey).dict().at("r").array().data<double>();
    for (std::int64_t e = 0; e < config_.num_envs; ++e) {
      if (ended_mask[e]) ended_returns->push_back(returns[e]);
    }
  }
  env_steps_ += config_.num_envs;
}

IterationStats DrqAlgorithm::iterate(const trainer::StopCheck& stop) {
  if (!started_) start();
  IterationStats stats;
  StepTimes times;
  double sample_s = 0.0;
  double update_s = 0.0;
  double critic_loss = 0.0, actor_loss = 0.0, q_mean = 0.0, target_mean = 0.0, entropy = 0.0;
  double alpha = trainer::ProgressRow::kNone;
  std::int64_t updates = 0, actor_updates = 0;
  const std::int64_t steps = config_.iteration_env_steps / config_.num_envs;
  bool stopped = false;
  for (std::int64_t s = 0; s < steps && !stopped; ++s) {
    choose_actions(times);
    step_env(&stats.episode_returns, times);
    if (env_steps_ < config_.seed_env_steps || !buffer_.can_sample()) {
      stopped = stop && stop(env_steps_);
      continue;
    }
    update_credit_ += static_cast<double>(config_.num_envs) * config_.updates_per_env_step;
    while (update_credit_ >= 1.0) {
      update_credit_ -= 1.0;
      auto start = Clock::now();
      buffer_.sample(config_.batch_size, replay_rng_, batch_);
      sample_s += seconds_since(start);
      start = Clock::now();
      const UpdateStats update = learner_.update(batch_, augmentation_, sampling_);
      update_s += seconds_since(start);
      critic_loss += update.critic_loss;
      if (!std::isnan(update.actor_loss)) {
        actor_loss += update.actor_loss;
        entropy += update.entropy;
        ++actor_updates;
      }
      alpha = update.alpha;
      q_mean += update.q_mean;
      target_mean += update.target_mean;
      ++updates;
      ++gradient_updates_;
      if (stop && stop(env_steps_)) {
        stopped = true;
        break;
      }
    }
    if (!stopped && stop) stopped = stop(env_steps_);
  }
  ++iterations_;
  stats.metrics = {
      {"critic_loss", mean_or_none(critic_loss, updates)},
      {"actor_loss", mean_or_none(actor_loss, actor_updates)},
      {"q_mean", mean_or_none(q_mean, updates)},
      {"target_mean", mean_or_none(target_mean, updates)},
      {"alpha", alpha},
      {"policy_entropy", mean_or_none(entropy, actor_updates)},
      {"gradient_updates", static_cast<double>(gradient_updates_)},
      {"updates_per_s", updates > 0 ? static_cast<double>(updates) / (sample_s + update_s)
                                    : trainer::ProgressRow::kNone},
      {"replay_transitions", static_cast<double>(buffer_.steps_added())},
      {"replay_mb", static_cast<double>(buffer_.bytes()) / 1e6},
      {"env_s", times.env},
      {"act_s", times.act},
      {"sample_s", sample_s},
      {"update_s", update_s}};
  return stats;
}

void DrqAlgorithm::set_progress(std::int64_t env_steps, std::int64_t updates) {
  env_steps_ = env_steps;
  iterations_ = updates;
}

std::vector<std::string> DrqAlgorithm::metric_names() const {
  return {"critic_loss",      "actor_loss",    "q_mean",
          "target_mean",      "alpha",         "policy_entropy",
          "gradient_updates", "updates_per_s", "replay_transitions",
          "replay_mb",        "env_s",         "act_s",
          "sample_s",         "update_s"};
}

void DrqAlgorithm::save(CheckpointBlobs& blobs, json& meta) {
  blobs["agent"] = trainer::save_blob(learner_.agent_ptr());
  blobs["actor_optimizer"] = trainer::save_blob(learner_.actor_optimizer());
  blobs["critic_optimizer"] = trainer::save_blob(learner_.critic_optimizer());
  blobs["rng_augmentation"] = trainer::generator_blob(augmentation_);
  blobs["rng_exploration"] = trainer::generator_blob(exploration_);
  blobs["rng_sampling"] = trainer::generator_blob(sampling_);
  blobs["alpha_optimizer"] = trainer::save_blob(learner_.alpha_optimizer());
  std::ostringstream replay_rng;
  replay_rng << replay_rng_;
  meta["drq"] = {{"replay_rng", replay_rng.str()},
                 {"update_credit", update_credit_},
                 {"gradient_updates", gradient_updates_}};
}

void DrqAlgorithm::restore(const LoadedCheckpoint& checkpoint, const json& meta) {
  std::shared_ptr<Agent> agent = learner_.agent_ptr();
  trainer::load_blob(checkpoint, "agent", agent);
  trainer::load_blob(checkpoint, "actor_optimizer", learner_.actor_optimizer());
  trainer::load_blob(checkpoint, "critic_optimizer", learner_.critic_optimizer());
  trainer::load_generator(checkpoint, "rng_augmentation", augmentation_);
  trainer::load_generator(checkpoint, "rng_exploration", exploration_);
  trainer::load_generator(checkpoint, "rng_sampling", sampling_);
  trainer::load_blob(checkpoint, "alpha_optimizer", learner_.alpha_optimizer());
  if (!meta.contains("drq")) {
    throw std::runtime_error(checkpoint.path.string() +
                             ": the checkpoint's meta has no \"drq\" member");
  }
  const json& own = meta.at("drq");
  std::istringstream replay_rng(own.at("replay_rng").get<std::string>());
  replay_rng >> replay_rng_;
  if (!replay_rng) {
    throw std::runtime_error(checkpoint.path.string() +
                             ": the checkpoint's replay_rng is not a generator state");
  }
  update_credit_ = own.at("update_credit").get<double>();
  gradient_updates_ = own.at("gradient_updates").get<std::int64_t>();
  learner_.set_updates(gradient_updates_);
}

bool DrqAlgorithm::env_action_log_complete() const {
  const auto batches = static_cast<std::size_t>(env_steps_ / config_.num_envs);
  return env_action_log_.size() == batches * actions_.array().nbytes();
}

void DrqAlgorithm::replay_env(const std::string& env_action_log) {
  if (started_) {
    throw std::logic_error("DrqAlgorithm::replay_env: the envs were already reset or stepped");
  }
  Array& action = actions_.array();
  const std::size_t batch_bytes = action.nbytes();
  const std::int64_t steps_done = env_steps_;
  const auto batches = static_cast<std::size_t>(steps_done / config_.num_envs);
  if (env_action_log.size() != batches * batch_bytes) {
    throw std::invalid_argument(
        "DrqAlgorithm::replay_env: an action log of " + std::to_string(batches) + " batches of " +
        std::to_string(batch_bytes) + " bytes (for " + std::to_string(steps_done) +
        " env steps) expected, got " + std::to_string(env_action_log.size()) + " bytes");
  }
  torch::NoGradGuard no_grad;
  env_steps_ = 0;
  start();
  StepTimes times;
  for (std::size_t b = 0; b < batches; ++b) {
    std::memcpy(action.raw_data(), env_action_log.data() + b * batch_bytes, batch_bytes);
    step_env(nullptr, times);
  }
  env_action_log_ = env_action_log;
}

std::uint64_t DrqAlgorithm::env_digest() const {
  if (!started_) return 0;
  std::uint64_t digest = 14695981039346656037ULL;  // FNV-1a, 64-bit
  const auto add = [&digest](const void* data, std::size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < size; ++k) digest = (digest ^ bytes[k]) * 1099511628211ULL;
  };
  for (const auto& [key, tensor] : current_obs_) {
    add(key.data(), key.size());
    const torch::Tensor contiguous = tensor.contiguous();
    add(contiguous.data_ptr(), contiguous.nbytes());
  }
  const std::vector<double>& returns = episodes_.episode_returns();
  const std::vector<std::int64_t>& lengths = episodes_.episode_lengths();
  add(returns.data(), returns.size() * sizeof(double));
  add(lengths.data(), lengths.size() * sizeof(std::int64_t));
  return digest;
}

// ---- DrqAlgorithmFactory -------------------------------------------------------------------

json DrqAlgorithmFactory::parse_config(const std::string& text) const {
  json parsed;
  try {
    parsed = json::parse(text);
  } catch (const json::parse_error& error) {
    throw std::invalid_argument(std::string("DrqConfig JSON: ") + error.what());
  }
  DrqConfig config;
  from_json(parsed, config);
  json out;
  to_json(out, config);
  return out;
}

int DrqAlgorithmFactory::set_threads(int requested) const {
  return trainer::set_torch_threads(requested);
}

std::unique_ptr<trainer::Algorithm> DrqAlgorithmFactory::make(
    vector::VectorEnv& env, const json& config, trainer::Communicator& communicator) const {
  if (communicator.world_size() > 1) {
    throw std::invalid_argument(
        "train --algo drq runs in one process; it was started as " +
        std::to_string(communicator.world_size()) +
        " ranks (--nproc or WORLD_SIZE). Data-parallel training is PPO's (--algo ppo)");
  }
  DrqConfig parsed;
  from_json(config, parsed);
  return std::make_unique<DrqAlgorithm>(env, parsed);
}

std::unique_ptr<trainer::Actor> DrqAlgorithmFactory::load_actor(
    const Space& observation_space, const Space& action_space, const json& config,
    const LoadedCheckpoint& checkpoint) const {
  DrqConfig parsed;
  from_json(config, parsed);
  auto agent =
      std::make_shared<Agent>(trainer::input_layout(observation_space, action_space,
                                                    parsed.frame_stack, "drq", "the run's env"),
                              parsed);
  trainer::load_blob(checkpoint, "agent", agent);
  agent->eval();
  return std::make_unique<DrqActor>(std::move(agent), parsed.seed + 4);
}

}  // namespace pixelgym::drq
