// The learning algorithm as a training run sees it (TrainingRun): what every algorithm offers the
// run — iterate over the run's env loop, its state for checkpoints, its config and the metrics it
// reports by name, and an Actor for evaluation — without torch, so that the run stays algorithm-
// and torch-free.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/envs/space.h"
#include "pixelgym/envs/value.h"
#include "pixelgym/envs/vector/vector_env.h"
#include "pixelgym/trainer/checkpoint_file.h"
#include "pixelgym/trainer/communicator.h"
#include "pixelgym/trainer/env_loop.h"
#include "pixelgym/trainer/progress_csv.h"
#include "pixelgym/trainer/settings_declaration.h"

namespace pixelgym::trainer {

/// What one Actor::act call sent to the env, for the evaluation's clipped-action figure.
struct ActCounts {
  /// Float (Box) actions: the action elements the policy put outside the action space's bounds
  /// (sent to the env clipped) and all the action elements; both 0 for integer actions.
  std::int64_t clipped_elements = 0;
  std::int64_t float_elements = 0;
};

/// A policy choosing actions for a vector env: what evaluation needs of an algorithm.
class Actor {
 public:
  virtual ~Actor() = default;
  /// Writes into `actions` (laid out as the vector env's action_space()) the actions for
  /// `observations` (the vector env's observation batch): the policy's most likely action when
  /// `deterministic`, else one sampled from it. Computes no gradients.
  virtual ActCounts act(const Value& observations, bool deterministic, Value& actions) = 0;
  /// The policy as a policy file's JSON (pixelgym/testing/mlp_policy.h) without "env_id",
  /// "env_kwargs" and "source", which the caller adds: for a policy that is an MLP over the
  /// observation's float keys, its deterministic action. Throws std::invalid_argument saying why
  /// this policy is not one (by default: none is).
  virtual nlohmann::json mlp_policy() const {
    throw std::invalid_argument(
        "expected a policy that is an MLP over vector observations (a drq run trained from "
        "state, --set obs_mode=state), got one of another kind");
  }
};

/// What one Algorithm::iterate did.
struct IterationStats {
  /// The returns of the episodes that ended during it (the sum of the rewards the algorithm was
  /// given), in the order they ended.
  std::vector<double> episode_returns;
  /// Its metrics by name, each one of Algorithm::metric_names() (progress.csv's columns after
  /// the run's); one it leaves out, or NaN (ProgressRow::kNone), is an empty field.
  std::map<std::string, double> metrics;
};

/// Asked by an iteration between its small steps (each env step batch, each gradient step), with
/// the env steps it has done so far (all envs, the run's before it included): the run reports
/// progress from it and answers true when the iteration must end now (the run's time budget is
/// spent, or it was interrupted). The iteration then ends as soon as what it did can be kept: a
/// shorter rollout learned from, fewer gradient steps; the run checkpoints it as any other.
using StopCheck = std::function<bool(std::int64_t env_steps)>;

/// A learning algorithm on a vector env, driven by a TrainingRun: the run calls iterate() until
/// its budget is spent, and checkpoints, resumes and evaluates through the calls below. The env
/// loop is the run's: it owns an EnvLoop (env_loop.h: the seeded reset, the action log, its
/// replay on resume, the env digest and the episode statistics) and lends it to the algorithm
/// (AlgorithmFactory::make), which steps the envs only through it. An algorithm that learns env
/// step by env step need not step it at all: SteppedAlgorithm (stepped_algorithm.h) is this
/// interface over a StepLearner's act / observe / learn (DrQ and DrQ-v2 are made so); PPO steps
/// the loop in its rollouts.
class Algorithm {
 public:
  virtual ~Algorithm() = default;

  /// Collects experience from the env and learns from it (PPO: one rollout, one update), asking
  /// `stop` (when set) between its steps; a stopped iteration still counts as one.
  virtual IterationStats iterate(const StopCheck& stop) = 0;

  /// Env steps done (all envs together) and iterations done (the run names and spaces its
  /// checkpoints by them, and records them as "updates").
  virtual std::int64_t env_steps() const = 0;
  virtual std::int64_t updates() const = 0;
  /// Sets both on resume, before restore() and the replay of the env actions.
  virtual void set_progress(std::int64_t env_steps, std::int64_t updates) = 0;

  /// The names of the metrics it reports (IterationStats::metrics), in order: progress.csv's
  /// columns after the run's (progress_base_columns). A resumed run keeps the columns of its
  /// progress.csv; a metric that is not one of them is refused by name (RunFolder).
  virtual std::vector<std::string> metric_names() const = 0;

  /// Adds its learning state to a checkpoint: blobs of its own (the run writes "config", "meta"
  /// and "env_actions") and members of the checkpoint's meta object (the run writes "env_steps",
  /// "updates", "wall_time_s", "recent_returns" and "env_digest").
  virtual void save(CheckpointBlobs& blobs, nlohmann::json& meta) = 0;
  /// Restores what save() wrote. Throws std::runtime_error naming checkpoint.path for a blob it
  /// needs that is not there.
  virtual void restore(const LoadedCheckpoint& checkpoint, const nlohmann::json& meta) = 0;

  /// A resume replays the checkpoint's env actions through the run's EnvLoop (so that the envs
  /// continue their episodes): the envs' first observations, then each replayed step with the
  /// actions it took. An algorithm that keeps what it sees (a replay buffer) takes them in here;
  /// by default it keeps nothing. Called after set_progress and restore, before iterate().
  virtual void replayed_reset(const Value& /*observations*/) {}
  virtual void replayed_step(const Value& /*actions*/, const vector::VectorStepResult& /*step*/) {}

  /// The policy as trained so far, for evaluation.
  virtual Actor& actor() = 0;

  /// A digest of the parameters (and buffers) learned, equal on every rank of a distributed run
  /// after every update; 0 when the algorithm has none to give.
  virtual std::uint64_t parameter_digest() const { return 0; }
  /// The blobs of save() that belong to one rank of a distributed run (its generators, ...);
  /// the others (parameters, optimizer state) are the same on every rank. A distributed
  /// checkpoint keeps rank 0's blobs and, for every other rank r, these blobs and its meta as
  /// "rank{r}.{name}" and "rank{r}.meta".
  virtual std::vector<std::string> rank_blobs() const { return {}; }
};

/// An algorithm's kind: its config, and how to build it to train or to act. Implemented once per
/// algorithm (ppo::PpoAlgorithmFactory).
class AlgorithmFactory {
 public:
  virtual ~AlgorithmFactory() = default;

  /// The member of config.json that holds the algorithm's config ("ppo").
  virtual std::string name() const = 0;
  /// The config given as JSON text, completed and validated: an object with every member (the
  /// ones not given at their defaults; "{}" gives the defaults), among them "seed" (seeds the
  /// algorithm and the envs: env i resets with seed + i), "num_envs" (envs stepped together) and
  /// "total_env_steps" (the run's length), which the run reads. Throws std::invalid_argument
  /// for bad JSON, an unknown member or a value out of range, naming it.
  virtual nlohmann::json parse_config(const std::string& text) const = 0;
  /// Sets the threads the algorithm computes with in this process, `requested` or, when 0, its
  /// default; returns the count in use.
  virtual int set_threads(int requested) const = 0;
  /// The algorithm, to train on the envs of `loop` (SameStep autoreset, config["num_envs"] envs,
  /// reset with config["seed"] + rank num_envs; the loop must outlive the algorithm) with
  /// `config` (as parse_config gives it), as one rank of `communicator`'s run (a
  /// SingleProcessCommunicator for one process; it must outlive the algorithm). Throws
  /// std::invalid_argument for an env it cannot train on, or a communicator of several ranks
  /// when it does not train distributed.
  virtual std::unique_ptr<Algorithm> make(EnvLoop& loop, const nlohmann::json& config,
                                          Communicator& communicator) const = 0;
  /// The policy saved in `checkpoint`, for an env of these spaces, to act only. Throws
  /// std::runtime_error naming checkpoint.path when a blob it needs is not there.
  virtual std::unique_ptr<Actor> load_actor(const Space& observation_space,
                                            const Space& action_space, const nlohmann::json& config,
                                            const LoadedCheckpoint& checkpoint) const = 0;
  /// Every setting of the config with its default, its range and what it does (`train
  /// --list-settings`): describe_settings of a config that declares its settings
  /// (pixelgym/trainer/settings_declaration.h). By default, the members of parse_config("{}")
  /// with their defaults alone.
  virtual std::vector<SettingDescription> settings() const {
    std::vector<SettingDescription> described;
    const nlohmann::json defaults = parse_config("{}");  // kept alive while iterated
    for (const auto& item : defaults.items()) {
      described.push_back({item.key(), item.value(), "", ""});
    }
    return described;
  }
};

}  // namespace pixelgym::trainer
