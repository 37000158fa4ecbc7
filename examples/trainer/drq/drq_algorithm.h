// DrQ-v2 behind the run's Algorithm interface (examples/trainer/run/algorithm.h): it steps a
// vector env, fills a replay buffer and updates a Learner; and the factory that builds it from
// config.json's "drq".
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

#include "examples/trainer/drq/drq.h"
#include "examples/trainer/torch_common/replay_buffer.h"
#include "pixelgym/trainer/algorithm.h"
#include "pixelgym/wrappers/vector/record_episode_statistics.h"

namespace pixelgym::drq {

/// An Agent acting for evaluation: the tanh of its Gaussian's mean (deterministic), or a sample
/// of the squashed Gaussian (a seeded generator of its own).
class DrqActor final : public trainer::Actor {
 public:
  /// Throws std::invalid_argument for a null agent.
  DrqActor(std::shared_ptr<Agent> agent, std::uint64_t seed);
  trainer::ActCounts act(const Value& observations, bool deterministic, Value& actions) override;

 private:
  std::shared_ptr<Agent> agent_;
  at::Generator sampling_;
};

/// DrQ on a vector env (SameStep autoreset, num_envs as config.num_envs) as an Algorithm.
///
/// iterate() takes config.iteration_env_steps env steps. Each step acts (uniform random actions
/// for the first seed_env_steps, then samples of the policy), adds the transitions to the replay
/// buffer (a step that ends an episode adds the episode's final observation, then the next
/// episode's first), and then makes updates_per_env_step updates per env step (the fraction
/// carried over), each from a batch sampled from the buffer. `stop` is asked after each env step
/// and each update: once it answers true the iteration ends there, the updates it did not make
/// left as credit for the next env steps. (This env loop is DrQ-v2's, copied: it moves into the
/// run, for both, when the run owns the env loop.)
///
/// Determinism: torch::manual_seed(seed) before the weights; the replay sampling draws from a
/// std::mt19937_64 seeded with seed, the augmentation from a torch generator seeded seed + 1,
/// the exploration (random actions and the policy's samples while training) from seed + 2 and
/// the update's samples from seed + 3; the envs reset with seed.
///
/// Checkpoint: blobs "agent" (torch::save of the Agent: encoder, heads, actor, critics, target
/// critics, log_alpha), "actor_optimizer", "critic_optimizer" (with the encoder),
/// "alpha_optimizer", "rng_augmentation", "rng_exploration", "rng_sampling"; meta "drq":
/// {"replay_rng" (the sampling generator's state as text), "update_credit",
/// "gradient_updates" (which also restores the learner's count, that spaces the actor's and the
/// target's updates)}. The replay buffer is not saved: replay_env, which replays the
/// checkpoint's env actions, puts the same transitions back in the same order, so a resumed run
/// is the run that did not stop.
///
/// Its metrics (progress.csv's columns after the run's): critic_loss, actor_loss, q_mean,
/// target_mean (means over the iteration's updates; actor_loss over its actor updates), alpha
/// (the temperature after the last update), policy_entropy (minus the mean log-probability of
/// the actor updates' samples), gradient_updates (all so far), updates_per_s, replay_transitions,
/// replay_mb, and where the iteration's time went: env_s, act_s, sample_s, update_s.
class DrqAlgorithm final : public trainer::Algorithm {
 public:
  /// Throws std::invalid_argument for a config that fails validate(), an env that does not
  /// autoreset in SameStep mode or has another num_envs, and as input_layout for the spaces.
  DrqAlgorithm(vector::VectorEnv& env, DrqConfig config);

  trainer::IterationStats iterate(const trainer::StopCheck& stop) override;
  std::int64_t env_steps() const override { return env_steps_; }
  std::int64_t updates() const override { return iterations_; }
  void set_progress(std::int64_t env_steps, std::int64_t updates) override;
  std::vector<std::string> metric_names() const override;
  void save(trainer::CheckpointBlobs& blobs, nlohmann::json& meta) override;
  void restore(const trainer::LoadedCheckpoint& checkpoint, const nlohmann::json& meta) override;
  const std::string& env_action_log() const override { return env_action_log_; }
  bool env_action_log_complete() const override;
  void replay_env(const std::string& env_action_log) override;
  std::uint64_t env_digest() const override;
  trainer::Actor& actor() override { return actor_; }

  Learner& learner() { return learner_; }
  const ReplayBuffer& buffer() const { return buffer_; }
  std::int64_t gradient_updates() const { return gradient_updates_; }

 private:
  struct StepTimes {
    double env = 0.0, act = 0.0;
  };
  // Resets the envs with the seed and adds their first observations.
  void start();
  // Steps the envs with actions_ (already in the log) and adds the transitions; returns the
  // step's ended episodes' returns.
  void step_env(std::vector<double>* ended_returns, StepTimes& times);
  // Chooses the next actions into actions_ and appends them to the log.
  void choose_actions(StepTimes& times);

  DrqConfig config_;
  vector::RecordEpisodeStatistics episodes_;
  Learner learner_;
  ReplayBuffer buffer_;
  ReplayBatch batch_;
  std::mt19937_64 replay_rng_;
  at::Generator augmentation_;
  at::Generator exploration_;
  at::Generator sampling_;
  Value actions_;                                     // laid out as the env's action_space()
  std::map<std::string, torch::Tensor> current_obs_;  // views of the env's observation batch
  std::string env_action_log_;
  bool started_ = false;
  std::int64_t env_steps_ = 0;
  std::int64_t iterations_ = 0;
  std::int64_t gradient_updates_ = 0;
  double update_credit_ = 0.0;
  DrqActor actor_;
};

/// DrQ's AlgorithmFactory: name "drq", the config a DrqConfig (to_json / from_json).
class DrqAlgorithmFactory final : public trainer::AlgorithmFactory {
 public:
  std::string name() const override { return "drq"; }
  nlohmann::json parse_config(const std::string& text) const override;
  /// trainer::set_torch_threads.
  int set_threads(int requested) const override;
  /// Throws std::invalid_argument for a communicator of several ranks: DrQ trains in one
  /// process (its replay buffer and updates are not shared across ranks).
  std::unique_ptr<trainer::Algorithm> make(vector::VectorEnv& env, const nlohmann::json& config,
                                           trainer::Communicator& communicator) const override;
  /// An Agent of the config for these spaces with the checkpoint's "agent".
  std::unique_ptr<trainer::Actor> load_actor(
      const Space& observation_space, const Space& action_space, const nlohmann::json& config,
      const trainer::LoadedCheckpoint& checkpoint) const override;
};

}  // namespace pixelgym::drq
