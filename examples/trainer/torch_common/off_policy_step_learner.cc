#include "examples/trainer/torch_common/off_policy_step_learner.h"

#include <ATen/CPUGeneratorImpl.h>

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "examples/trainer/torch_common/observation_tensors.h"
#include "examples/trainer/torch_common/torch_state.h"

namespace pixelgym::trainer {

OffPolicyStepLearner::OffPolicyStepLearner(const vector::VectorEnv& env,
                                           const OffPolicySettings& settings,
                                           std::int64_t batch_rows, OffPolicyNames names)
    : settings_(settings),
      names_(std::move(names)),
      input_((require_off_policy_env(settings, env, names_.algorithm.c_str(), batch_rows),
              input_layout(env.single_observation_space(), env.single_action_space(),
                           settings.frame_stack, names_.algorithm, env.name()))),
      buffer_(input_.replay_layout(), settings.num_envs, settings.replay_capacity, settings.n_step,
              settings.gamma),
      replay_rng_(settings.seed),
      augmentation_(at::detail::createCPUGenerator(settings.seed + 1)),
      exploration_(at::detail::createCPUGenerator(settings.seed + 2)),
      update_generator_(at::detail::createCPUGenerator(settings.seed + 3)),
      updates_(settings.num_envs, settings.updates_per_env_step, settings.seed_env_steps) {}

torch::Tensor OffPolicyStepLearner::explore(const ObservationTensors& obs, std::int64_t,
                                            at::Generator& exploration) {
  return shared_agent()->act(obs, false, &exploration);
}

void OffPolicyStepLearner::begin(const Value& observations) {
  add_first_observations(buffer_, input_, observations);
}

void OffPolicyStepLearner::act(const Value& observations, std::int64_t env_steps, Value& actions) {
  torch::Tensor unit;
  if (env_steps < settings_.seed_env_steps) {
    unit = torch::rand({settings_.num_envs, input_.action_size}, exploration_) * 2.0 - 1.0;
  } else {
    unit = explore(observation_tensors(observations), env_steps, exploration_);
  }
  write_env_actions(*shared_agent(), unit, actions);
}

void OffPolicyStepLearner::observe(const Value& actions, const vector::VectorStepResult& step) {
  torch::NoGradGuard no_grad;
  // The buffer keeps actions in [-1, 1], as the actor gives them, from what the env was sent
  // (so that a replayed log fills the buffer with the same bytes).
  const torch::Tensor unit =
      shared_agent()
          ->unit_action(array_tensor(actions.array()).reshape({settings_.num_envs, -1}))
          .contiguous();
  add_env_step(buffer_, input_, unit.data_ptr<float>(), step, names_.algorithm);
}

bool OffPolicyStepLearner::learn(std::int64_t env_steps, const StopCheck& stop) {
  env_steps_ = env_steps;
  return updates_.run(env_steps, buffer_, settings_.batch_size, replay_rng_, batch_, stop,
                      [&](const ReplayBatch& batch) {
                        const UpdateSummary summary = update(batch, env_steps);
                        sums_.critic_loss += summary.critic_loss;
                        if (!std::isnan(summary.actor_loss)) {
                          sums_.actor_loss += summary.actor_loss;
                          ++actor_updates_;
                        }
                        sums_.q_mean += summary.q_mean;
                        sums_.target_mean += summary.target_mean;
                      });
}

std::map<std::string, double> OffPolicyStepLearner::end_iteration(const LoopTimes& times) {
  const std::int64_t updates = updates_.iteration_updates();
  const UpdateSummary sums = std::exchange(sums_, UpdateSummary{});
  const std::int64_t actor_updates = std::exchange(actor_updates_, 0);
  std::map<std::string, double> metrics = update_metrics(updates, actor_updates, env_steps_);
  metrics["critic_loss"] = mean_or_none(sums.critic_loss, updates);
  metrics["actor_loss"] = mean_or_none(sums.actor_loss, actor_updates);
  metrics["q_mean"] = mean_or_none(sums.q_mean, updates);
  metrics["target_mean"] = mean_or_none(sums.target_mean, updates);
  updates_.end_iteration(buffer_, times, metrics);
  return metrics;
}

std::vector<std::string> OffPolicyStepLearner::metric_names() const {
  std::vector<std::string> names = {"critic_loss", "actor_loss", "q_mean", "target_mean"};
  for (const std::string& name : update_metric_names()) names.push_back(name);
  for (const std::string& name : ReplayUpdates::metric_names()) names.push_back(name);
  return names;
}

void OffPolicyStepLearner::save(CheckpointBlobs& blobs, nlohmann::json& meta) {
  blobs["agent"] = save_blob(shared_agent());
  for (const auto& [name, optimizer] : optimizers()) {
    if (optimizer != nullptr) blobs[name] = save_blob(*optimizer);
  }
  blobs["rng_augmentation"] = generator_blob(augmentation_);
  blobs["rng_exploration"] = generator_blob(exploration_);
  blobs[names_.update_generator] = generator_blob(update_generator_);
  std::ostringstream replay_rng;
  replay_rng << replay_rng_;
  meta[names_.algorithm] = {{"replay_rng", replay_rng.str()},
                            {"update_credit", updates_.credit()},
                            {"gradient_updates", updates_.total()}};
}

void OffPolicyStepLearner::restore(const LoadedCheckpoint& checkpoint, const nlohmann::json& meta) {
  std::shared_ptr<OffPolicyAgent> agent = shared_agent();
  load_blob(checkpoint, "agent", agent);
  for (const auto& [name, optimizer] : optimizers()) {
    if (optimizer != nullptr) load_blob(checkpoint, name, *optimizer);
  }
  load_generator(checkpoint, "rng_augmentation", augmentation_);
  load_generator(checkpoint, "rng_exploration", exploration_);
  load_generator(checkpoint, names_.update_generator, update_generator_);
  if (!meta.contains(names_.algorithm)) {
    throw std::runtime_error(checkpoint.path.string() + ": the checkpoint's meta has no \"" +
                             names_.algorithm + "\" member");
  }
  const nlohmann::json& own = meta.at(names_.algorithm);
  std::istringstream replay_rng(own.at("replay_rng").get<std::string>());
  replay_rng >> replay_rng_;
  if (!replay_rng) {
    throw std::runtime_error(checkpoint.path.string() +
                             ": the checkpoint's replay_rng is not a generator state");
  }
  updates_.restore(own.at("update_credit").get<double>(),
                   own.at("gradient_updates").get<std::int64_t>());
  restored_updates(updates_.total());
}

Actor& OffPolicyStepLearner::actor() {
  if (!actor_) actor_ = std::make_unique<OffPolicyActor>(shared_agent(), settings_.seed + 4);
  return *actor_;
}

}  // namespace pixelgym::trainer
