// The run's side of an off-policy learner, written once: it acts (uniform random actions for the
// seed steps, then the agent's exploring ones), fills a replay buffer from the env steps the run
// takes (and from those it replays on a resume), makes the updates that are due, reports the
// replay metrics and saves and restores all of it but the networks' update. DrQ and DrQ-v2 derive
// from OffPolicyStepLearner and supply the agent, the update and its metrics.
#pragma once

#include <ATen/core/Generator.h>
#include <torch/torch.h>

#include <cstdint>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "examples/trainer/torch_common/input_layout.h"
#include "examples/trainer/torch_common/off_policy_agent.h"
#include "examples/trainer/torch_common/off_policy_settings.h"
#include "examples/trainer/torch_common/replay_buffer.h"
#include "examples/trainer/torch_common/replay_updates.h"
#include "pixelgym/trainer/stepped_algorithm.h"

namespace pixelgym::trainer {

/// The names an off-policy learner's run uses: the algorithm ("drq": in errors, and its
/// checkpoint meta's member) and the checkpoint blob of its update's generator ("rng_sampling").
struct OffPolicyNames {
  std::string algorithm;
  std::string update_generator;
};

/// What an update reports that every off-policy learner's metrics have.
struct UpdateSummary {
  double critic_loss = 0.0;
  /// NaN when the update did not step the actor.
  double actor_loss = 0.0;
  double q_mean = 0.0;       // mean of Q1 over the batch
  double target_mean = 0.0;  // mean of the target
};

/// An optimizer and the checkpoint blob it is saved as.
using NamedOptimizer = std::pair<std::string, torch::optim::Optimizer*>;

/// A StepLearner over a replay buffer (SameStep autoreset, num_envs as settings.num_envs).
/// Each env step: act (uniform random actions for the first seed_env_steps, then explore()),
/// add the transitions to the buffer (a step that ends an episode adds the episode's final
/// observation, then the next episode's first), then make updates_per_env_step updates per env
/// step (the fraction carried over), each from batch_size transitions sampled from the buffer,
/// asking `stop` after each (the updates not made are left as credit for the next env steps).
///
/// Determinism: the replay sampling draws from a std::mt19937_64 seeded with seed, the
/// augmentation from a torch generator seeded seed + 1, the exploration from seed + 2, the
/// update's own draws from seed + 3 and the evaluation actor's from seed + 4.
///
/// Checkpoint: blobs "agent" (torch::save of the agent), each of optimizers(), and
/// "rng_augmentation", "rng_exploration" and names.update_generator; meta member
/// names.algorithm: {"replay_rng" (the sampling generator's state as text), "update_credit",
/// "gradient_updates"}. The replay buffer is not saved: the run's replay of the checkpoint's env
/// actions puts the same transitions back in the same order (observe), so a resumed run is the
/// run that did not stop.
///
/// Metrics: critic_loss, actor_loss, q_mean, target_mean (means over the iteration's updates;
/// actor_loss over those that stepped the actor), then update_metric_names(), then
/// ReplayUpdates::metric_names().
class OffPolicyStepLearner : public StepLearner {
 public:
  void begin(const Value& observations) override;
  void act(const Value& observations, std::int64_t env_steps, Value& actions) override;
  void observe(const Value& actions, const vector::VectorStepResult& step) override;
  bool learn(std::int64_t env_steps, const StopCheck& stop) override;
  std::map<std::string, double> end_iteration(const LoopTimes& times) override;
  std::vector<std::string> metric_names() const override;
  void save(CheckpointBlobs& blobs, nlohmann::json& meta) override;
  void restore(const LoadedCheckpoint& checkpoint, const nlohmann::json& meta) override;
  /// Made on first use, from shared_agent().
  Actor& actor() override;

  const ReplayBuffer& buffer() const { return buffer_; }
  std::int64_t gradient_updates() const { return updates_.total(); }

 protected:
  /// `settings` already validated; `batch_rows` the transitions an update encodes with
  /// gradients (for the memory check). Throws std::invalid_argument as require_off_policy_env
  /// and input_layout do. The algorithm's agent is made after this (its constructor), from
  /// input().
  OffPolicyStepLearner(const vector::VectorEnv& env, const OffPolicySettings& settings,
                       std::int64_t batch_rows, OffPolicyNames names);

  /// The env's input layout.
  const InputLayout& input() const { return input_; }
  at::Generator& augmentation() { return augmentation_; }
  at::Generator& update_generator() { return update_generator_; }

  /// The algorithm's agent.
  virtual std::shared_ptr<OffPolicyAgent> shared_agent() const = 0;
  /// Actions in [-1, 1] to explore with after the seed steps, `env_steps` into the run, drawn
  /// from `exploration` (default: the agent's act).
  virtual torch::Tensor explore(const ObservationTensors& obs, std::int64_t env_steps,
                                at::Generator& exploration);
  /// One update from `batch`, `env_steps` into the run; the algorithm keeps the sums of its own
  /// metrics.
  virtual UpdateSummary update(const ReplayBatch& batch, std::int64_t env_steps) = 0;
  /// The iteration's own metrics from those sums, over its `updates` updates and `actor_updates`
  /// actor steps (the sums start over), `env_steps` as the last learn() was given them; and their
  /// names.
  virtual std::map<std::string, double> update_metrics(std::int64_t updates,
                                                       std::int64_t actor_updates,
                                                       std::int64_t env_steps) = 0;
  virtual std::vector<std::string> update_metric_names() const = 0;
  /// The optimizers and their blobs (null ones are left out).
  virtual std::vector<NamedOptimizer> optimizers() = 0;
  /// A checkpoint's count of updates made was restored.
  virtual void restored_updates(std::int64_t /*updates*/) {}

 private:
  OffPolicySettings settings_;
  OffPolicyNames names_;
  InputLayout input_;
  ReplayBuffer buffer_;
  ReplayBatch batch_;
  std::mt19937_64 replay_rng_;
  at::Generator augmentation_;
  at::Generator exploration_;
  at::Generator update_generator_;
  ReplayUpdates updates_;
  std::int64_t env_steps_ = 0;  // as the last learn() was given them
  UpdateSummary sums_;          // over the iteration's updates
  std::int64_t actor_updates_ = 0;
  std::unique_ptr<OffPolicyActor> actor_;
};

/// An OffPolicyStepLearner that owns the algorithm's `Learner`, made from (input(), config) once
/// the shared part is: DrQ's and DrQ-v2's step learners derive from this. `Learner` has
/// agent_ptr(), the agent the evaluation actor uses.
template <typename Learner>
class OffPolicyStepLearnerWith : public OffPolicyStepLearner {
 public:
  Learner& learner() { return learner_; }

 protected:
  /// `config` an OffPolicySettings with validate() (checked here, before anything is made).
  template <typename Config>
  OffPolicyStepLearnerWith(const vector::VectorEnv& env, const Config& config,
                           std::int64_t batch_rows, OffPolicyNames names)
      : OffPolicyStepLearner(env, validated(config), batch_rows, std::move(names)),
        learner_(input(), config) {}

  std::shared_ptr<OffPolicyAgent> shared_agent() const override { return learner_.agent_ptr(); }

 private:
  Learner learner_;
};

}  // namespace pixelgym::trainer
