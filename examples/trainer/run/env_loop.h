// The run's side of a vector env: reset with the run's seed, step with an algorithm's actions,
// and what a checkpoint needs to put the envs back where they were — the log of every action
// batch, its replay, the digest of where the envs are, and the episodes' statistics. Written once
// for every algorithm that learns step by step (SteppedAlgorithm), without torch.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "pixelgym/envs/value.h"
#include "pixelgym/envs/vector/vector_env.h"
#include "pixelgym/wrappers/vector/record_episode_statistics.h"

namespace pixelgym::trainer {

/// A 64-bit FNV-1a digest of where a vector env is: the arrays of `observations` (a bare Array
/// under the key "", a Dict's arrays in key order, each key's bytes before its array's) and the
/// returns and lengths of the episodes in progress. The digest a checkpoint keeps
/// (meta["env_digest"]); equal to the one PPO and DrQ-v2 computed over their observation
/// tensors, so that the checkpoints of earlier runs still compare. Throws std::invalid_argument
/// for a Tuple, or a Dict holding anything but Arrays.
std::uint64_t env_digest(const Value& observations, const std::vector<double>& episode_returns,
                         const std::vector<std::int64_t>& episode_lengths);

/// An episode that ended: its return (the sum of the env's rewards) and its length in steps.
struct EndedEpisode {
  double episode_return = 0.0;
  std::int64_t length = 0;
};

/// Steps a vector env for a training run (TrainingRun owns one and lends it to the algorithm):
/// resets it with `seed` (env i with seed + i), steps it with the action batches it is given, keeps
/// each batch in its action log and records the episodes (a RecordEpisodeStatistics of its own over
/// the env, so that the env may record its own). The env must outlive it.
class EnvLoop {
 public:
  /// Observes `env` (not owned). `episode_key` is the infos key of its episode statistics.
  EnvLoop(vector::VectorEnv& env, std::uint64_t seed, const std::string& episode_key);

  /// Whether the envs were reset (by reset() or replay()).
  bool started() const { return started_; }
  /// Resets the envs with the seed; returns their first observations.
  const Value& reset();
  /// Steps the envs with `actions` (laid out as the env's action_space()) and appends them to
  /// the log. Throws std::logic_error before reset().
  const vector::VectorStepResult& step(const Value& actions);
  /// The episodes that `step` (this loop's last step) ended, in env order.
  std::vector<EndedEpisode> ended_episodes(const vector::VectorStepResult& step) const;
  /// Their returns alone.
  std::vector<double> ended_returns(const vector::VectorStepResult& step) const;

  /// The observations the envs are at (the last reset's or step's); an empty Value before
  /// reset().
  const Value& observations() const { return observations_; }
  /// A batch of zero actions laid out as the env's action_space(), to fill and step with.
  Value zero_actions() const { return env_->action_space().zeros(); }
  /// The env batches stepped since the first reset (replayed ones included).
  std::int64_t batches() const { return batches_; }
  std::int64_t num_envs() const { return env_->num_envs(); }
  /// The env it steps, and the seed it resets it with (env i with seed + i).
  vector::VectorEnv& env() const { return *env_; }
  std::uint64_t seed() const { return seed_; }
  /// The bytes of one action batch in the log.
  std::size_t batch_bytes() const { return batch_bytes_; }

  /// Every action batch sent to the envs since their first reset, as bytes.
  const std::string& action_log() const { return action_log_; }
  /// Whether the log covers `env_steps` env steps (all envs together).
  bool action_log_covers(std::int64_t env_steps) const;
  /// Resets the envs and steps them with the batches of `log` (as action_log gives it),
  /// calling `on_step` with each batch and its step; the log becomes this loop's. Throws
  /// std::logic_error when the envs were already reset, and std::invalid_argument when the log
  /// does not hold `env_steps` env steps of whole batches, naming both sizes.
  void replay(const std::string& log, std::int64_t env_steps,
              const std::function<void(const Value& first_observations)>& on_reset,
              const std::function<void(const Value& actions, const vector::VectorStepResult& step)>&
                  on_step);
  /// env_digest of where the envs are; 0 before the first reset.
  std::uint64_t digest() const;

 private:
  vector::VectorEnv* env_;
  vector::RecordEpisodeStatistics episodes_;
  std::size_t batch_bytes_;  // of one action batch
  std::string episode_key_;
  std::uint64_t seed_;
  Value observations_;
  std::string action_log_;
  std::int64_t batches_ = 0;
  bool started_ = false;
};

}  // namespace pixelgym::trainer
