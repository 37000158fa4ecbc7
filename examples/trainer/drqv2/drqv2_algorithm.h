// DrQ-v2 as the run's learner (pixelgym/trainer/stepped_algorithm.h): it acts, fills a replay
// buffer from the env steps the run takes and updates a Learner; and the factory that builds it
// from config.json's "drqv2".
#pragma once

#include <ATen/core/Generator.h>
#include <torch/torch.h>

#include <cstdint>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "examples/trainer/drqv2/drqv2.h"
#include "examples/trainer/torch_common/replay_buffer.h"
#include "examples/trainer/torch_common/replay_updates.h"
#include "pixelgym/trainer/algorithm.h"
#include "pixelgym/trainer/progress_csv.h"
#include "pixelgym/trainer/stepped_algorithm.h"

namespace pixelgym::drqv2 {

/// An Agent acting for evaluation: its mean action (deterministic), or with noise of std
/// `stochastic_std` (seeded generator of its own).
class DrqV2Actor final : public trainer::Actor {
 public:
  /// Throws std::invalid_argument for a null agent.
  DrqV2Actor(std::shared_ptr<Agent> agent, double stochastic_std, std::uint64_t seed);
  trainer::ActCounts act(const Value& observations, bool deterministic, Value& actions) override;

 private:
  std::shared_ptr<Agent> agent_;
  double stochastic_std_;
  at::Generator noise_;
};

/// DrQ-v2's side of the run's env loop (trainer::SteppedAlgorithm steps the vector env, SameStep
/// autoreset, num_envs as config.num_envs, config.iteration_env_steps env steps an iteration).
/// Each env step: act (uniform random actions for the first seed_env_steps, then the policy's
/// with the scheduled noise), add the transitions to the replay buffer (a step that ends an
/// episode adds the episode's final observation, then the next episode's first), then make
/// updates_per_env_step updates per env step (the fraction carried over), each from a batch
/// sampled from the buffer, asking `stop` after each (the updates not made are left as credit
/// for the next env steps).
///
/// Determinism: torch::manual_seed(seed) before the weights; the replay sampling draws from a
/// std::mt19937_64 seeded with seed, the augmentation from a torch generator seeded seed + 1,
/// the exploration (random and noisy actions) from seed + 2 and the update's noise from
/// seed + 3; the envs reset with seed.
///
/// Checkpoint: blobs "agent" (torch::save of the Agent: encoder, actor, critic, target
/// critic), "encoder_optimizer" (when there is an image), "actor_optimizer",
/// "critic_optimizer", "rng_augmentation", "rng_exploration", "rng_noise"; meta "drqv2":
/// {"replay_rng" (the sampling generator's state as text), "update_credit",
/// "gradient_updates"}. The replay buffer is not saved: it holds what the env steps put into it,
/// and the run's replay of the checkpoint's env actions puts the same transitions back in the
/// same order (observe), so a resumed run is the run that did not stop.
///
/// Its metrics (progress.csv's columns after the run's; runs before metrics were named by their
/// algorithm also have PPO's five loss columns, left empty): critic_loss, actor_loss, q_mean,
/// target_mean (means over the iteration's updates), noise_std, gradient_updates (all so far),
/// updates_per_s (this iteration's updates over the seconds spent in them), replay_transitions,
/// replay_mb (the buffer's allocation), and where the iteration's time went: env_s, act_s,
/// sample_s, update_s.
class DrqV2StepLearner final : public trainer::StepLearner {
 public:
  /// Throws std::invalid_argument for a config that fails validate(), an env that does not
  /// autoreset in SameStep mode or has another num_envs, and as input_layout for the spaces.
  DrqV2StepLearner(const vector::VectorEnv& env, DrqV2Config config);

  void begin(const Value& observations) override;
  void act(const Value& observations, std::int64_t env_steps, Value& actions) override;
  void observe(const Value& actions, const vector::VectorStepResult& step) override;
  bool learn(std::int64_t env_steps, const trainer::StopCheck& stop) override;
  std::map<std::string, double> end_iteration(const trainer::LoopTimes& times) override;
  std::vector<std::string> metric_names() const override;
  void save(trainer::CheckpointBlobs& blobs, nlohmann::json& meta) override;
  void restore(const trainer::LoadedCheckpoint& checkpoint, const nlohmann::json& meta) override;
  trainer::Actor& actor() override { return actor_; }

  Learner& learner() { return learner_; }
  const ReplayBuffer& buffer() const { return buffer_; }
  std::int64_t gradient_updates() const { return updates_.total(); }

 private:
  // Sums over the iteration's updates, for its metrics.
  struct IterationSums {
    double critic_loss = 0.0, actor_loss = 0.0, q_mean = 0.0, target_mean = 0.0;
  };

  DrqV2Config config_;
  Learner learner_;
  ReplayBuffer buffer_;
  ReplayBatch batch_;
  std::mt19937_64 replay_rng_;
  at::Generator augmentation_;
  at::Generator exploration_;
  at::Generator noise_;
  trainer::ReplayUpdates updates_;
  std::int64_t env_steps_ = 0;  // as the last learn() was given them, for noise_std
  IterationSums sums_;
  DrqV2Actor actor_;
};

/// DrQ-v2's AlgorithmFactory: name "drqv2", the config a DrqV2Config (to_json / from_json).
class DrqV2AlgorithmFactory final : public trainer::AlgorithmFactory {
 public:
  std::string name() const override { return "drqv2"; }
  nlohmann::json parse_config(const std::string& text) const override;
  /// trainer::set_torch_threads.
  int set_threads(int requested) const override;
  /// Throws std::invalid_argument for a communicator of several ranks: DrQ-v2 trains in one
  /// process (its replay buffer and updates are not shared across ranks).
  std::unique_ptr<trainer::Algorithm> make(trainer::EnvLoop& loop, const nlohmann::json& config,
                                           trainer::Communicator& communicator) const override;
  /// An Agent of the config for these spaces with the checkpoint's "agent".
  std::unique_ptr<trainer::Actor> load_actor(
      const Space& observation_space, const Space& action_space, const nlohmann::json& config,
      const trainer::LoadedCheckpoint& checkpoint) const override;
};

}  // namespace pixelgym::drqv2
