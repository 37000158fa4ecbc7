// A policy's evaluation: seeded episodes on one env built as the run's, optionally recorded, and
// the evaluation of a saved checkpoint (`pixelgym eval`).
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <vector>

#include "examples/trainer/run/algorithm.h"
#include "examples/trainer/run/run_settings.h"

namespace pixelgym::trainer {

/// Which episodes an evaluation plays.
struct EvaluationRequest {
  std::int64_t episodes = 1;  // at least 1
  std::uint64_t seed = 0;     // episode e resets with seed + e
  bool stochastic = false;    // sample actions instead of taking the most likely one
  /// Records the first episode to this .mp4 (RecordVideo: H.264, named after the path's stem).
  std::optional<std::filesystem::path> video;
};

/// What an evaluation measured.
struct PolicyEvaluation {
  double mean = 0.0;  // of the episodes' returns
  double std = 0.0;   // population standard deviation of the returns
  std::vector<double> returns;
  /// Box actions: the fraction of action elements the policy put outside the bounds (sent to
  /// the env clipped). Near 1, the policy acts bang-bang at the bounds; 0 for Discrete.
  double clipped_fraction = 0.0;
};

/// Plays request.episodes episodes of `actor` on one env built as the run's (make_run_env, in a
/// SyncVectorEnv without autoreset), each to its end. Throws what the env throws.
PolicyEvaluation evaluate(Actor& actor, const RunSettings& settings,
                          const EnvKwargsParser& parse_sets, const EvaluationRequest& request);

/// summary.json's "evaluation": {"episodes", "seed", "deterministic", "return_mean",
/// "return_std", "returns", "clipped_action_fraction"}.
nlohmann::json evaluation_json(const PolicyEvaluation& evaluation,
                               const EvaluationRequest& request);

/// A checkpoint's evaluation.
struct CheckpointEvaluation {
  std::filesystem::path checkpoint;  // the file evaluated
  RunSettings settings;              // the run's, which built the env (settings.algorithm: its
                                     // algorithm's name)
  PolicyEvaluation evaluation;
};

/// Evaluates the policy of a checkpoint: `run_or_checkpoint` is a run folder (its latest valid
/// checkpoint; newer invalid ones are reported to `errors` as "eval: skipping {path}: {reason}")
/// or a checkpoint file. The env and the algorithm's config come from the checkpoint's "config"
/// blob, else from config.json beside it; the algorithm computes with the run's thread count
/// (a float sum over another count can round differently, and the returns would then differ from
/// the run's summary.json). Throws std::runtime_error when there is no valid checkpoint, the
/// file is not a valid checkpoint (read_checkpoint), or the settings are nowhere to be found or
/// name none of `algorithms` (algorithm_of).
CheckpointEvaluation evaluate_checkpoint(const AlgorithmFactories& algorithms,
                                         const EnvKwargsParser& parse_sets,
                                         const std::filesystem::path& run_or_checkpoint,
                                         const EvaluationRequest& request, std::ostream& errors);

}  // namespace pixelgym::trainer
