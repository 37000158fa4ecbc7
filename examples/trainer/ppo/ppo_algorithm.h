// PPO behind the run's Algorithm interface (examples/trainer/run/algorithm.h): a Trainer and its
// Policy as a TrainingRun drives them, and the factory that builds them from config.json's "ppo".
#pragma once

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "examples/trainer/ppo/policy.h"
#include "examples/trainer/ppo/ppo.h"
#include "pixelgym/trainer/algorithm.h"

namespace pixelgym::ppo {

/// A Policy acting for evaluation: ActResult::env_action written into the env's actions.
class PpoActor final : public trainer::Actor {
 public:
  /// Throws std::invalid_argument for a null policy.
  explicit PpoActor(std::shared_ptr<Policy> policy);
  trainer::ActCounts act(const Value& observations, bool deterministic, Value& actions) override;

 private:
  std::shared_ptr<Policy> policy_;
};

/// A Trainer on a vector env as an Algorithm: iterate(stop) is collect(stop) then update(stop).
///
/// Checkpoint: blobs "model" (the policy's parameters and buffers, torch::save), "optimizer"
/// (Adam's state), "rng_sampling" and "rng_augmentation" (TrainerRngState), and meta
/// "reward_scaling" {"mean", "var", "count", "returns"} (RewardScaling; JSON numbers keep a
/// double exactly). Its metrics (progress.csv's columns after the run's): policy_loss,
/// value_loss, entropy, approx_kl, clip_fraction (UpdateStats), explained_variance, grad_norm,
/// learning_rate,
/// and where the iteration's time went: env_s in the vector env's step/reset, act_s in the
/// policy's forward passes while collecting, update_s in the PPO epochs, and allreduce_s the part
/// of update_s spent in the collectives of a distributed run (UpdateStats::allreduce_seconds; 0
/// in one process).
class PpoAlgorithm final : public trainer::Algorithm {
 public:
  /// Steps the run's `loop`. Throws as Trainer's constructor.
  PpoAlgorithm(trainer::EnvLoop& loop, PpoConfig config, trainer::Communicator& communicator);

  trainer::IterationStats iterate(const trainer::StopCheck& stop) override;
  std::int64_t env_steps() const override { return trainer_.env_steps(); }
  std::int64_t updates() const override { return trainer_.updates(); }
  void set_progress(std::int64_t env_steps, std::int64_t updates) override;
  std::vector<std::string> metric_names() const override;
  void save(trainer::CheckpointBlobs& blobs, nlohmann::json& meta) override;
  void restore(const trainer::LoadedCheckpoint& checkpoint, const nlohmann::json& meta) override;
  trainer::Actor& actor() override { return actor_; }
  std::uint64_t parameter_digest() const override { return trainer_.parameter_digest(); }
  /// The generators' states: "rng_sampling", "rng_augmentation" (the reward scaling's
  /// discounted returns, per env, are in each rank's meta).
  std::vector<std::string> rank_blobs() const override;

  Trainer& trainer() { return trainer_; }

 private:
  Trainer trainer_;
  PpoActor actor_;
};

/// PPO's AlgorithmFactory: name "ppo", the config a PpoConfig (to_json / from_json).
class PpoAlgorithmFactory final : public trainer::AlgorithmFactory {
 public:
  std::string name() const override { return "ppo"; }
  nlohmann::json parse_config(const std::string& text) const override;
  /// trainer::set_torch_threads.
  int set_threads(int requested) const override;
  /// Trains distributed (see Trainer) with a communicator of several ranks.
  std::unique_ptr<trainer::Algorithm> make(trainer::EnvLoop& loop, const nlohmann::json& config,
                                           trainer::Communicator& communicator) const override;
  /// A Policy of config["policy"] with the checkpoint's "model", in eval mode.
  std::unique_ptr<trainer::Actor> load_actor(
      const Space& observation_space, const Space& action_space, const nlohmann::json& config,
      const trainer::LoadedCheckpoint& checkpoint) const override;
  /// PpoConfig's declared settings, policy's as "policy.NAME".
  std::vector<trainer::SettingDescription> settings() const override {
    return trainer::describe_settings(PpoConfig{});
  }
};

}  // namespace pixelgym::ppo
