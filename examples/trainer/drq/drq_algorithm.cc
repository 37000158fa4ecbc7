#include "examples/trainer/drq/drq_algorithm.h"

#include <ATen/CPUGeneratorImpl.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "examples/trainer/torch_common/input_layout.h"
#include "examples/trainer/torch_common/observation_tensors.h"
#include "examples/trainer/torch_common/off_policy_networks.h"
#include "examples/trainer/torch_common/torch_state.h"

namespace pixelgym::drq {

using trainer::ActCounts;
using trainer::CheckpointBlobs;
using trainer::IterationStats;
using trainer::LoadedCheckpoint;

namespace {

using nlohmann::json;

const DrqConfig& checked(const DrqConfig& config, const vector::VectorEnv& env) {
  config.validate();
  trainer::require_off_policy_env(config, env, "drq", config.batch_size * config.augmented_copies);
  return config;
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

// ---- DrqStepLearner ------------------------------------------------------------------------

DrqStepLearner::DrqStepLearner(const vector::VectorEnv& env, DrqConfig config)
    : config_(checked(config, env)),
      learner_(trainer::input_layout(env.single_observation_space(), env.single_action_space(),
                                     config_.frame_stack, "drq", env.name()),
               config_),
      buffer_(learner_.agent().input().replay_layout(), config_.num_envs, config_.replay_capacity,
              config_.n_step, config_.gamma),
      replay_rng_(config_.seed),
      augmentation_(at::detail::createCPUGenerator(config_.seed + 1)),
      exploration_(at::detail::createCPUGenerator(config_.seed + 2)),
      sampling_(at::detail::createCPUGenerator(config_.seed + 3)),
      updates_(config_.num_envs, config_.updates_per_env_step, config_.seed_env_steps),
      actor_(learner_.agent_ptr(), config_.seed + 4) {}

void DrqStepLearner::begin(const Value& observations) {
  trainer::add_first_observations(buffer_, learner_.agent().input(), observations);
}

void DrqStepLearner::act(const Value& observations, std::int64_t env_steps, Value& actions) {
  Agent& agent = learner_.agent();
  torch::Tensor unit;
  if (env_steps < config_.seed_env_steps) {
    unit = torch::rand({config_.num_envs, agent.input().action_size}, exploration_) * 2.0 - 1.0;
  } else {
    unit = agent.act(trainer::observation_tensors(observations), false, &exploration_);
  }
  Array& action = actions.array();
  const torch::Tensor chosen =
      agent.env_action(unit).to(trainer::torch_dtype(action.dtype())).contiguous();
  std::memcpy(action.raw_data(), chosen.data_ptr(), action.nbytes());
}

void DrqStepLearner::observe(const Value& actions, const vector::VectorStepResult& step) {
  torch::NoGradGuard no_grad;
  // The buffer keeps actions in [-1, 1], as the actor gives them, from what the env was sent
  // (so that a replayed log fills the buffer with the same bytes).
  const torch::Tensor unit =
      learner_.agent()
          .unit_action(trainer::array_tensor(actions.array()).reshape({config_.num_envs, -1}))
          .contiguous();
  trainer::add_env_step(buffer_, learner_.agent().input(), unit.data_ptr<float>(), step, "drq");
}

bool DrqStepLearner::learn(std::int64_t env_steps, const trainer::StopCheck& stop) {
  return updates_.run(env_steps, buffer_, config_.batch_size, replay_rng_, batch_, stop,
                      [this](const ReplayBatch& batch) {
                        const UpdateStats update = learner_.update(batch, augmentation_, sampling_);
                        sums_.critic_loss += update.critic_loss;
                        if (!std::isnan(update.actor_loss)) {
                          sums_.actor_loss += update.actor_loss;
                          sums_.entropy += update.entropy;
                          ++sums_.actor_updates;
                        }
                        sums_.alpha = update.alpha;
                        sums_.q_mean += update.q_mean;
                        sums_.target_mean += update.target_mean;
                      });
}

std::map<std::string, double> DrqStepLearner::end_iteration(const trainer::LoopTimes& times) {
  const IterationSums sums = std::exchange(sums_, IterationSums{});
  const std::int64_t updates = updates_.iteration_updates();
  std::map<std::string, double> metrics = {
      {"critic_loss", trainer::mean_or_none(sums.critic_loss, updates)},
      {"actor_loss", trainer::mean_or_none(sums.actor_loss, sums.actor_updates)},
      {"q_mean", trainer::mean_or_none(sums.q_mean, updates)},
      {"target_mean", trainer::mean_or_none(sums.target_mean, updates)},
      {"alpha", sums.alpha},
      {"policy_entropy", trainer::mean_or_none(sums.entropy, sums.actor_updates)}};
  updates_.end_iteration(buffer_, times, metrics);
  return metrics;
}

std::vector<std::string> DrqStepLearner::metric_names() const {
  std::vector<std::string> names = {"critic_loss", "actor_loss", "q_mean",
                                    "target_mean", "alpha",      "policy_entropy"};
  for (const std::string& name : trainer::ReplayUpdates::metric_names()) names.push_back(name);
  return names;
}

void DrqStepLearner::save(CheckpointBlobs& blobs, json& meta) {
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
                 {"update_credit", updates_.credit()},
                 {"gradient_updates", updates_.total()}};
}

void DrqStepLearner::restore(const LoadedCheckpoint& checkpoint, const json& meta) {
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
  updates_.restore(own.at("update_credit").get<double>(),
                   own.at("gradient_updates").get<std::int64_t>());
  learner_.set_updates(updates_.total());
}

// ---- DrqAlgorithmFactory -------------------------------------------------------------------

json DrqAlgorithmFactory::parse_config(const std::string& text) const {
  return trainer::parse_off_policy_config<DrqConfig>(text, "DrqConfig");
}

int DrqAlgorithmFactory::set_threads(int requested) const {
  return trainer::set_torch_threads(requested);
}

std::unique_ptr<trainer::Algorithm> DrqAlgorithmFactory::make(
    trainer::EnvLoop& loop, const json& config, trainer::Communicator& communicator) const {
  trainer::require_one_process(communicator, "drq");
  DrqConfig parsed;
  from_json(config, parsed);
  return std::make_unique<trainer::SteppedAlgorithm>(
      loop, trainer::SteppedSettings{parsed.iteration_env_steps},
      std::make_unique<DrqStepLearner>(loop.env(), parsed));
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
