// A policy's evaluation: seeded episodes on one env built as the run's, optionally recorded, and
// the evaluation of a saved checkpoint (`pixelgym eval`).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "pixelgym/trainer/algorithm.h"
#include "pixelgym/trainer/run_settings.h"

namespace pixelgym::trainer {

/// The seed of a run's evaluations (the final one, summary.json's, and those during training):
/// the run's seed plus this.
constexpr std::uint64_t kEvaluationSeedOffset = 1'000'000;

/// Which episodes an evaluation plays.
struct EvaluationRequest {
  std::int64_t episodes = 1;  // at least 1
  std::uint64_t seed = 0;     // episode e resets with seed + e
  bool stochastic = false;    // sample actions instead of taking the most likely one
  /// Records the first episode to this .mp4 (RecordVideo: H.264, named after the path's stem).
  std::optional<std::filesystem::path> video;
  /// Asked before each episode after the first with the episodes played so far: false ends the
  /// evaluation there (a time budget). Absent: every episode is played.
  std::function<bool(std::int64_t episodes_done)> more;
  /// Called after every env step (progress reports). Absent: nothing.
  std::function<void()> on_step;
};

/// What an evaluation measured.
struct PolicyEvaluation {
  double mean = 0.0;  // of the episodes' returns
  double std = 0.0;   // population standard deviation of the returns
  std::vector<double> returns;
  /// Box actions: the fraction of action elements the policy put outside the bounds (sent to
  /// the env clipped). Near 1, the policy acts bang-bang at the bounds; 0 for Discrete.
  double clipped_fraction = 0.0;
  std::int64_t steps = 0;         // env steps played, all episodes together
  std::vector<double> episode_s;  // each episode's wall time (the first's with its video)
};

/// What evaluation episodes cost on this machine now, for planning a time budget.
struct EvaluationCost {
  double setup_s = 0.0;        // building the env, once per evaluation
  double step_s = 0.0;         // one env step with the policy's action
  double video_step_s = 0.0;   // one env step recorded to a video
  double video_fixed_s = 0.0;  // opening and finishing a video file
  /// The longest an episode can be: the env's max_episode_steps (TimeLimit), else 1000.
  std::int64_t episode_steps = 1000;
  bool episode_steps_known = false;  // whether the env has a TimeLimit

  /// Seconds of one episode at its longest, recorded to a video or not.
  double episode_seconds(bool video) const;
  /// Seconds of an evaluation of `episodes` episodes at their longest, the first recorded when
  /// `video`.
  double evaluation_seconds(std::int64_t episodes, bool video) const;
};

/// Times `steps` env steps of `actor` (deterministic) on one env built as the run's, then
/// `steps` more recorded to a scratch video in `scratch_folder` (removed after), calling
/// `on_step` (when set) after each. Throws what the env throws.
EvaluationCost measure_evaluation_cost(Actor& actor, const RunSettings& settings,
                                       const std::filesystem::path& scratch_folder,
                                       std::int64_t steps,
                                       const std::function<void()>& on_step = {});

/// The final evaluation a time budget allows: the most of `asked` episodes (at least one) that
/// fit in `seconds` at `cost`, the first recorded to the video while one video episode fits
/// (else none is recorded), and `note`, a sentence saying what was given up ("" when nothing).
struct FinalEvaluationPlan {
  std::int64_t episodes = 1;
  bool video = true;
  double seconds = 0.0;  // its cost at `cost`
  std::string note;
};
FinalEvaluationPlan plan_final_evaluation(double seconds, const EvaluationCost& cost,
                                          std::int64_t asked);

/// Plays request.episodes episodes of `actor` on one env built as the run's (make_run_env, in a
/// SyncVectorEnv without autoreset), each to its end. Throws what the env throws.
PolicyEvaluation evaluate(Actor& actor, const RunSettings& settings,
                          const EvaluationRequest& request);

/// summary.json's "evaluation": {"episodes", "seed", "deterministic", "return_mean",
/// "return_std", "returns", "clipped_action_fraction"}.
nlohmann::json evaluation_json(const PolicyEvaluation& evaluation,
                               const EvaluationRequest& request);

/// Which episodes a checkpoint's evaluation plays: absent members as summary.json's evaluation
/// (see evaluate_checkpoint).
struct CheckpointEvaluationRequest {
  std::optional<std::int64_t> episodes;
  std::optional<std::uint64_t> seed;
  bool stochastic = false;
  std::optional<std::filesystem::path> video;
  /// Another env to play in, with the run's kwargs and wrappers; its spaces must be the run's.
  std::optional<std::string> env_id;
  /// Env kwargs as KEY=VALUE over the run's (parse_kwargs).
  std::vector<std::string> env_sets;
};

/// A checkpoint's evaluation.
struct CheckpointEvaluation {
  std::filesystem::path checkpoint;  // the file evaluated
  RunSettings settings;              // the run's, which built the env (settings.algorithm: its
                                     // algorithm's name), with the request's env and kwargs
  EvaluationRequest request;         // the episodes played
  /// Where the episodes and seed not given came from: "summary.json" (the run's final
  /// evaluation, of this checkpoint) or "the run's settings" (seed + 1,000,000, eval_episodes).
  std::string defaults_from;
  PolicyEvaluation evaluation;
};

/// Evaluates the policy of a checkpoint: `run_or_checkpoint` is a run folder (its latest valid
/// checkpoint; newer invalid ones are reported to `errors` as "eval: skipping {path}: {reason}")
/// or a checkpoint file. The env and the algorithm's config come from the checkpoint's "config"
/// blob, else from config.json beside it; the algorithm computes with the run's thread count
/// (a float sum over another count can round differently, and the returns would then differ from
/// the run's summary.json). Throws std::runtime_error when there is no valid checkpoint, the
/// file is not a valid checkpoint (read_checkpoint), or the settings are nowhere to be found or
/// name none of `algorithms` (algorithm_of). Episodes and seed not given are those of the run's
/// final evaluation, so that the returns agree with summary.json's: summary.json's when the
/// run folder has one of this checkpoint's env steps, else the run's eval_episodes from its seed
/// + kEvaluationSeedOffset.
CheckpointEvaluation evaluate_checkpoint(const AlgorithmFactories& algorithms,
                                         const std::filesystem::path& run_or_checkpoint,
                                         const CheckpointEvaluationRequest& request,
                                         std::ostream& errors);

/// The policy of a checkpoint, found as evaluate_checkpoint finds it, and its run's settings.
struct CheckpointPolicy {
  std::filesystem::path checkpoint;  // the file loaded
  RunSettings settings;
  std::int64_t env_steps = 0;  // the checkpoint's (0 when it does not say)
  std::unique_ptr<Actor> actor;
};

/// Loads the policy of `run_or_checkpoint` (a run folder or a checkpoint file) as
/// evaluate_checkpoint does, for `command` ("export"), which its errors and skip lines name.
CheckpointPolicy load_checkpoint_policy(const AlgorithmFactories& algorithms,
                                        const std::filesystem::path& run_or_checkpoint,
                                        const std::string& command, std::ostream& errors);

}  // namespace pixelgym::trainer
