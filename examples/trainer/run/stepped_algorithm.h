// An Algorithm that steps the run's env loop for a learner: a StepLearner acts, observes each env
// step and learns when it is due, and SteppedAlgorithm steps the run's EnvLoop for it (the action
// log, replay, digest and episode returns are the loop's). DrQ and DrQ-v2 are StepLearners; an
// algorithm outside the tree can be one too, without torch.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pixelgym/trainer/algorithm.h"
#include "pixelgym/trainer/env_loop.h"

namespace pixelgym::trainer {

/// Where an iteration's env loop spent its time, in seconds.
struct LoopTimes {
  /// Stepping the envs (rendering included).
  double env = 0.0;
  /// Choosing the actions (StepLearner::act).
  double act = 0.0;
};

/// A learner that SteppedAlgorithm drives, env step by env step.
class StepLearner {
 public:
  virtual ~StepLearner() = default;
  /// The envs were reset (at the run's start, or at the start of a replay): their first
  /// observations.
  virtual void begin(const Value& observations) = 0;
  /// Writes into `actions` (zeroed, laid out as the env's action_space()) the actions to
  /// explore with from `observations`, `env_steps` env steps into the run.
  virtual void act(const Value& observations, std::int64_t env_steps, Value& actions) = 0;
  /// The envs took `actions` and gave `step` (SameStep autoreset: an ended episode's last
  /// observation is in infos["final_obs"]). Also called for each replayed step of a resume, with
  /// the logged actions; act was not asked for those.
  virtual void observe(const Value& actions, const vector::VectorStepResult& step) = 0;
  /// Makes the updates due after an env step, `env_steps` env steps into the run, asking `stop`
  /// (when set) after each; returns true when `stop` answered true (the updates not made stay
  /// due).
  virtual bool learn(std::int64_t env_steps, const StopCheck& stop) = 0;
  /// The metrics of the iteration that ends now (each one of metric_names()), given where its
  /// env loop spent its time; starts the next iteration's.
  virtual std::map<std::string, double> end_iteration(const LoopTimes& times) = 0;
  /// As Algorithm's.
  virtual std::vector<std::string> metric_names() const = 0;
  virtual void save(CheckpointBlobs& blobs, nlohmann::json& meta) = 0;
  virtual void restore(const LoadedCheckpoint& checkpoint, const nlohmann::json& meta) = 0;
  virtual Actor& actor() = 0;
  virtual std::uint64_t parameter_digest() const { return 0; }
};

/// What SteppedAlgorithm needs of the run's config.
struct SteppedSettings {
  /// Env steps (all envs together) of one iteration: a progress.csv row, and the unit of
  /// checkpoint_every. A multiple of the env's num_envs.
  std::int64_t iteration_env_steps = 0;
};

/// An Algorithm made of the run's EnvLoop and a StepLearner. iterate() takes
/// settings.iteration_env_steps env steps; each: act, step the envs, observe, learn. `stop` is
/// asked after each env step (through learn, after each update): once it answers true the
/// iteration ends there. Its metrics are the learner's.
class SteppedAlgorithm final : public Algorithm {
 public:
  /// Steps `loop` (not owned; it must outlive the algorithm). Throws std::invalid_argument for
  /// a null learner or an iteration that is not a positive multiple of the env's num_envs.
  SteppedAlgorithm(EnvLoop& loop, SteppedSettings settings, std::unique_ptr<StepLearner> learner);

  IterationStats iterate(const StopCheck& stop) override;
  std::int64_t env_steps() const override { return env_steps_; }
  std::int64_t updates() const override { return iterations_; }
  void set_progress(std::int64_t env_steps, std::int64_t updates) override;
  std::vector<std::string> metric_names() const override { return learner_->metric_names(); }
  void save(CheckpointBlobs& blobs, nlohmann::json& meta) override { learner_->save(blobs, meta); }
  void restore(const LoadedCheckpoint& checkpoint, const nlohmann::json& meta) override {
    learner_->restore(checkpoint, meta);
  }
  /// The learner begins and observes the replayed steps (a replay buffer refills).
  void replayed_reset(const Value& observations) override { learner_->begin(observations); }
  void replayed_step(const Value& actions, const vector::VectorStepResult& step) override {
    learner_->observe(actions, step);
  }
  Actor& actor() override { return learner_->actor(); }
  std::uint64_t parameter_digest() const override { return learner_->parameter_digest(); }

  StepLearner& learner() { return *learner_; }

 private:
  SteppedSettings settings_;
  EnvLoop* loop_;
  std::unique_ptr<StepLearner> learner_;
  Value actions_;
  std::int64_t env_steps_ = 0;
  std::int64_t iterations_ = 0;
};

}  // namespace pixelgym::trainer
