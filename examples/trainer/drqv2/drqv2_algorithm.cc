#include "examples/trainer/drqv2/drqv2_algorithm.h"

#include <ATen/CPUGeneratorImpl.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "examples/trainer/torch_common/input_layout.h"
#include "examples/trainer/torch_common/observation_tensors.h"
#include "examples/trainer/torch_common/torch_state.h"

namespace pixelgym::drqv2 {

using trainer::ActCounts;
using trainer::CheckpointBlobs;
using trainer::IterationStats;
using trainer::LoadedCheckpoint;

namespace {

using nlohmann::json;

const DrqV2Config& checked(const DrqV2Config& config, const vector::VectorEnv& env) {
  config.validate();
  trainer::require_off_policy_env(config, env, "drqv2", config.batch_size);
  return config;
}

}  // namespace

// ---- DrqV2Actor ------------------------------------------------------------------------------

DrqV2Actor::DrqV2Actor(std::shared_ptr<Agent> agent, double stochastic_std, std::uint64_t seed)
    : agent_(std::move(agent)),
      stochastic_std_(stochastic_std),
      noise_(at::detail::createCPUGenerator(seed)) {
  if (!agent_) throw std::invalid_argument("DrqV2Actor: the agent is null");
}

ActCounts DrqV2Actor::act(const Value& observations, bool deterministic, Value& actions) {
  const torch::Tensor unit = agent_->act(trainer::observation_tensors(observations), deterministic,
                                         stochastic_std_, &noise_);
  Array& action = actions.array();
  const torch::Tensor chosen =
      agent_->env_action(unit).to(trainer::torch_dtype(action.dtype())).contiguous();
  std::memcpy(action.raw_data(), chosen.data_ptr(), action.nbytes());
  // The tanh policy's actions lie within the bounds: none is clipped.
  return {0, unit.numel()};
}

// ---- DrqV2StepLearner ----------------------------------------------------------------------

DrqV2StepLearner::DrqV2StepLearner(const vector::VectorEnv& env, DrqV2Config config)
    : config_(checked(config, env)),
      learner_(input_layout(env.single_observation_space(), env.single_action_space(),
                            config_.frame_stack, "drqv2", env.name()),
               config_),
      buffer_(learner_.agent().input().replay_layout(), config_.num_envs, config_.replay_capacity,
              config_.n_step, config_.gamma),
      replay_rng_(config_.seed),
      augmentation_(at::detail::createCPUGenerator(config_.seed + 1)),
      exploration_(at::detail::createCPUGenerator(config_.seed + 2)),
      noise_(at::detail::createCPUGenerator(config_.seed + 3)),
      updates_(config_.num_envs, config_.updates_per_env_step, config_.seed_env_steps),
      actor_(learner_.agent_ptr(), config_.noise_end, config_.seed + 4) {}

void DrqV2StepLearner::begin(const Value& observations) {
  trainer::add_first_observations(buffer_, learner_.agent().input(), observations);
}

void DrqV2StepLearner::act(const Value& observations, std::int64_t env_steps, Value& actions) {
  Agent& agent = learner_.agent();
  torch::Tensor unit;
  if (env_steps < config_.seed_env_steps) {
    unit = torch::rand({config_.num_envs, agent.input().action_size}, exploration_) * 2.0 - 1.0;
  } else {
    unit = agent.act(trainer::observation_tensors(observations), false,
                     config_.noise_std(env_steps), &exploration_);
  }
  Array& action = actions.array();
  const torch::Tensor chosen =
      agent.env_action(unit).to(trainer::torch_dtype(action.dtype())).contiguous();
  std::memcpy(action.raw_data(), chosen.data_ptr(), action.nbytes());
}

void DrqV2StepLearner::observe(const Value& actions, const vector::VectorStepResult& step) {
  torch::NoGradGuard no_grad;
  // The buffer keeps actions in [-1, 1], as the actor gives them, from what the env was sent
  // (so that a replayed log fills the buffer with the same bytes).
  const torch::Tensor unit =
      learner_.agent()
          .unit_action(trainer::array_tensor(actions.array()).reshape({config_.num_envs, -1}))
          .contiguous();
  trainer::add_env_step(buffer_, learner_.agent().input(), unit.data_ptr<float>(), step, "drqv2");
}

bool DrqV2StepLearner::learn(std::int64_t env_steps, const trainer::StopCheck& stop) {
  env_steps_ = env_steps;
  return updates_.run(env_steps, buffer_, config_.batch_size, replay_rng_, batch_, stop,
                      [this, env_steps](const ReplayBatch& batch) {
                        const UpdateStats update =
                            learner_.update(batch, env_steps, augmentation_, noise_);
                        sums_.critic_loss += update.critic_loss;
                        sums_.actor_loss += update.actor_loss;
                        sums_.q_mean += update.q_mean;
                        sums_.target_mean += update.target_mean;
                      });
}

std::map<std::string, double> DrqV2StepLearner::end_iteration(const trainer::LoopTimes& times) {
  const IterationSums sums = std::exchange(sums_, IterationSums{});
  const std::int64_t updates = updates_.iteration_updates();
  std::map<std::string, double> metrics = {
      {"critic_loss", trainer::mean_or_none(sums.critic_loss, updates)},
      {"actor_loss", trainer::mean_or_none(sums.actor_loss, updates)},
      {"q_mean", trainer::mean_or_none(sums.q_mean, updates)},
      {"target_mean", trainer::mean_or_none(sums.target_mean, updates)},
      {"noise_std", config_.noise_std(env_steps_)}};
  updates_.end_iteration(buffer_, times, metrics);
  return metrics;
}

std::vector<std::string> DrqV2StepLearner::metric_names() const {
  std::vector<std::string> names = {"critic_loss", "actor_loss", "q_mean", "target_mean",
                                    "noise_std"};
  for (const std::string& name : trainer::ReplayUpdates::metric_names()) names.push_back(name);
  return names;
}

void DrqV2StepLearner::save(CheckpointBlobs& blobs, json& meta) {
  blobs["agent"] = trainer::save_blob(learner_.agent_ptr());
  if (torch::optim::Adam* encoder = learner_.encoder_optimizer()) {
    blobs["encoder_optimizer"] = trainer::save_blob(*encoder);
  }
  blobs["actor_optimizer"] = trainer::save_blob(learner_.actor_optimizer());
  blobs["critic_optimizer"] = trainer::save_blob(learner_.critic_optimizer());
  blobs["rng_augmentation"] = trainer::generator_blob(augmentation_);
  blobs["rng_exploration"] = trainer::generator_blob(exploration_);
  blobs["rng_noise"] = trainer::generator_blob(noise_);
  std::ostringstream replay_rng;
  replay_rng << replay_rng_;
  meta["drqv2"] = {{"replay_rng", replay_rng.str()},
                   {"update_credit", updates_.credit()},
                   {"gradient_updates", updates_.total()}};
}

void DrqV2StepLearner::restore(const LoadedCheckpoint& checkpoint, const json& meta) {
  std::shared_ptr<Agent> agent = learner_.agent_ptr();
  trainer::load_blob(checkpoint, "agent", agent);
  if (torch::optim::Adam* encoder = learner_.encoder_optimizer()) {
    trainer::load_blob(checkpoint, "encoder_optimizer", *encoder);
  }
  trainer::load_blob(checkpoint, "actor_optimizer", learner_.actor_optimizer());
  trainer::load_blob(checkpoint, "critic_optimizer", learner_.critic_optimizer());
  trainer::load_generator(checkpoint, "rng_augmentation", augmentation_);
  trainer::load_generator(checkpoint, "rng_exploration", exploration_);
  trainer::load_generator(checkpoint, "rng_noise", noise_);
  if (!meta.contains("drqv2")) {
    throw std::runtime_error(checkpoint.path.string() +
                             ": the checkpoint's meta has no \"drqv2\" member");
  }
  const json& own = meta.at("drqv2");
  std::istringstream replay_rng(own.at("replay_rng").get<std::string>());
  replay_rng >> replay_rng_;
  if (!replay_rng) {
    throw std::runtime_error(checkpoint.path.string() +
                             ": the checkpoint's replay_rng is not a generator state");
  }
  updates_.restore(own.at("update_credit").get<double>(),
                   own.at("gradient_updates").get<std::int64_t>());
}

// ---- DrqV2AlgorithmFactory -------------------------------------------------------------------

json DrqV2AlgorithmFactory::parse_config(const std::string& text) const {
  return trainer::parse_off_policy_config<DrqV2Config>(text, "DrqV2Config");
}

int DrqV2AlgorithmFactory::set_threads(int requested) const {
  return trainer::set_torch_threads(requested);
}

std::unique_ptr<trainer::Algorithm> DrqV2AlgorithmFactory::make(
    trainer::EnvLoop& loop, const json& config, trainer::Communicator& communicator) const {
  trainer::require_one_process(communicator, "drqv2");
  DrqV2Config parsed;
  from_json(config, parsed);
  return std::make_unique<trainer::SteppedAlgorithm>(
      loop, trainer::SteppedSettings{parsed.iteration_env_steps},
      std::make_unique<DrqV2StepLearner>(loop.env(), parsed));
}

std::unique_ptr<trainer::Actor> DrqV2AlgorithmFactory::load_actor(
    const Space& observation_space, const Space& action_space, const json& config,
    const LoadedCheckpoint& checkpoint) const {
  DrqV2Config parsed;
  from_json(config, parsed);
  auto agent = std::make_shared<Agent>(
      input_layout(observation_space, action_space, parsed.frame_stack, "drqv2", "the run's env"),
      parsed);
  trainer::load_blob(checkpoint, "agent", agent);
  agent->eval();
  return std::make_unique<DrqV2Actor>(std::move(agent), parsed.noise_end, parsed.seed + 4);
}

}  // namespace pixelgym::drqv2
