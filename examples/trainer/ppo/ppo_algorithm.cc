#include "examples/trainer/ppo/ppo_algorithm.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "examples/trainer/torch_common/torch_state.h"

namespace pixelgym::ppo {

using trainer::ActCounts;
using trainer::Actor;
using trainer::Algorithm;
using trainer::CheckpointBlobs;
using trainer::IterationStats;
using trainer::LoadedCheckpoint;

namespace {

using nlohmann::json;

}  // namespace

PpoActor::PpoActor(std::shared_ptr<Policy> policy) : policy_(std::move(policy)) {
  if (!policy_) throw std::invalid_argument("PpoActor: the policy is null");
}

ActCounts PpoActor::act(const Value& observations, bool deterministic, Value& actions) {
  torch::NoGradGuard no_grad;
  const ActResult act = policy_->act(observation_tensors(observations), deterministic);
  Array& action = actions.array();
  const torch::Tensor chosen = act.env_action.to(torch_dtype(action.dtype())).contiguous();
  std::memcpy(action.raw_data(), chosen.data_ptr(), action.nbytes());
  ActCounts counts;
  if (act.action.is_floating_point()) {
    counts.clipped_elements = act.clipped_elements();
    counts.float_elements = act.action.numel();
  }
  return counts;
}

PpoAlgorithm::PpoAlgorithm(trainer::EnvLoop& loop, PpoConfig config,
                           trainer::Communicator& communicator)
    : trainer_(loop, std::move(config), communicator), actor_(trainer_.policy_ptr()) {}

std::vector<std::string> PpoAlgorithm::rank_blobs() const {
  return {"rng_sampling", "rng_augmentation"};
}

IterationStats PpoAlgorithm::iterate(const trainer::StopCheck& stop) {
  const RolloutStats rollout = trainer_.collect(stop);
  const auto update_start = std::chrono::steady_clock::now();
  const UpdateStats update = trainer_.update(stop);
  const double update_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - update_start).count();
  IterationStats stats;
  for (const Episode& episode : rollout.episodes) {
    stats.episode_returns.push_back(episode.episode_return);
  }
  stats.metrics = {{"policy_loss", update.policy_loss},
                   {"value_loss", update.value_loss},
                   {"entropy", update.entropy},
                   {"approx_kl", update.approx_kl},
                   {"clip_fraction", update.clip_fraction},
                   {"explained_variance", update.explained_variance},
                   {"grad_norm", update.grad_norm},
                   {"learning_rate", update.learning_rate},
                   {"env_s", rollout.env_seconds},
                   {"act_s", rollout.policy_seconds},
                   {"update_s", update_s},
                   {"allreduce_s", update.allreduce_seconds}};
  return stats;
}

void PpoAlgorithm::set_progress(std::int64_t env_steps, std::int64_t updates) {
  trainer_.set_progress(env_steps, updates);
}

std::vector<std::string> PpoAlgorithm::metric_names() const {
  return {"policy_loss",        "value_loss", "entropy",       "approx_kl", "clip_fraction",
          "explained_variance", "grad_norm",  "learning_rate", "env_s",     "act_s",
          "update_s",           "allreduce_s"};
}

void PpoAlgorithm::save(CheckpointBlobs& blobs, json& meta) {
  blobs["model"] = trainer::save_blob(trainer_.policy_ptr());
  blobs["optimizer"] = trainer::save_blob(trainer_.optimizer());
  const TrainerRngState rng = trainer_.rng_state();
  blobs["rng_sampling"] = trainer::save_blob(rng.sampling);
  blobs["rng_augmentation"] = trainer::save_blob(rng.augmentation);
  const RewardScaling scaling = trainer_.reward_scaling();
  meta["reward_scaling"] = {{"mean", scaling.statistics.mean[0]},
                            {"var", scaling.statistics.var[0]},
                            {"count", scaling.statistics.count},
                            {"returns", scaling.returns}};
}

void PpoAlgorithm::restore(const LoadedCheckpoint& checkpoint, const json& meta) {
  trainer::load_blob(checkpoint, "model", trainer_.policy_ptr());
  trainer::load_blob(checkpoint, "optimizer", trainer_.optimizer());
  TrainerRngState rng;
  trainer::load_blob(checkpoint, "rng_sampling", rng.sampling);
  trainer::load_blob(checkpoint, "rng_augmentation", rng.augmentation);
  trainer_.set_rng_state(rng);
  const json& scaling_json = meta.at("reward_scaling");
  RewardScaling scaling;
  scaling.statistics.mean = {scaling_json.at("mean").get<double>()};
  scaling.statistics.var = {scaling_json.at("var").get<double>()};
  scaling.statistics.count = scaling_json.at("count").get<double>();
  scaling.returns = scaling_json.at("returns").get<std::vector<double>>();
  trainer_.set_reward_scaling(std::move(scaling));
}

json PpoAlgorithmFactory::parse_config(const std::string& text) const {
  return json::parse(config_to_json(config_from_json(text)));
}

int PpoAlgorithmFactory::set_threads(int requested) const {
  return trainer::set_torch_threads(requested);
}

std::unique_ptr<Algorithm> PpoAlgorithmFactory::make(trainer::EnvLoop& loop, const json& config,
                                                     trainer::Communicator& communicator) const {
  return std::make_unique<PpoAlgorithm>(loop, config_from_json(config.dump()), communicator);
}

std::unique_ptr<Actor> PpoAlgorithmFactory::load_actor(const Space& observation_space,
                                                       const Space& action_space,
                                                       const json& config,
                                                       const LoadedCheckpoint& checkpoint) const {
  auto policy = std::make_shared<Policy>(observation_space, action_space,
                                         config_from_json(config.dump()).policy);
  trainer::load_blob(checkpoint, "model", policy);
  policy->eval();
  return std::make_unique<PpoActor>(std::move(policy));
}

}  // namespace pixelgym::ppo
