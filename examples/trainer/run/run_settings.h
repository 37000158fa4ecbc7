// What a training run is (config.json): the env, the run's own settings and the algorithm's
// config; and the envs built from it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pixelgym/envs/env.h"
#include "pixelgym/envs/params.h"
#include "pixelgym/envs/vector/vector_env.h"
#include "pixelgym/trainer/algorithm.h"

namespace pixelgym::trainer {

/// The settings of a run, as config.json holds them (with the same names, but `wraps`' "wrap",
/// and the algorithm's config under `algorithm`).
struct RunSettings {
  std::string env_id;
  /// The env's kwargs, typed (the command line parses `--set` into them: parse_kwargs); in
  /// config.json an object of JSON booleans, integers, floats and strings.
  Params env_kwargs;
  std::vector<std::string> wraps;      // wrapper specs, the first innermost
  int num_threads = 2;                 // the training env's worker threads (AsyncVectorEnv)
  int torch_threads = 0;               // the algorithm's threads (AlgorithmFactory::set_threads)
  std::int64_t checkpoint_every = 10;  // updates
  std::int64_t keep_checkpoints = 3;   // the newest kept, 0: all
  double minutes = 0.0;                // the run's first wall-time budget; 0: no time limit
  std::int64_t eval_episodes = 5;      // episodes of the final evaluation
  /// Evaluations during training (eval.csv): every eval_every env steps (0: none), over
  /// eval_every_episodes episodes each.
  std::int64_t eval_every = 0;
  std::int64_t eval_every_episodes = 5;
  /// An evaluation during training is skipped while those of this process have taken more than
  /// this share of its wall time (in (0, 1]; 1: never skipped).
  double eval_max_share = 0.1;
  /// The ranks of a data-parallel run (train --nproc, or WORLD_SIZE), each stepping num_envs()
  /// envs; 1: one process. config.json has "world_size" only when it is above 1.
  int world_size = 1;
  /// The algorithm's name (AlgorithmFactory::name) and its config (AlgorithmFactory::
  /// parse_config: every member present, "seed", "num_envs" and "total_env_steps" among them).
  std::string algorithm;
  nlohmann::json algorithm_config = nlohmann::json::object();

  /// The config's "seed", "num_envs" and "total_env_steps".
  std::uint64_t seed() const;
  std::int64_t num_envs() const;
  std::int64_t total_env_steps() const;
};

/// config.json's settings object.
nlohmann::json settings_to_json(const RunSettings& settings);

/// Params as a JSON object (bool, integer, float and string members) and back. kwargs_from_json
/// throws std::invalid_argument naming the member that is not one of the four.
nlohmann::json kwargs_to_json(const Params& kwargs);
Params kwargs_from_json(const nlohmann::json& object);

/// The settings of config.json's object `in` (read from `where`) for `algorithm`: its config
/// is the member algorithm.name(), read by algorithm.parse_config. The env's kwargs are
/// "env_kwargs"; a config written before they were kept typed has "set" (KEY=VALUE strings)
/// instead, read as `--set` is (parse_kwargs, with the env's declared types). Absent
/// "torch_threads": 0; absent "keep_checkpoints": 0 (keep all); absent "eval_every": 0 (none),
/// "eval_max_share": 0.1. Throws std::runtime_error "{where}: not a pixelgym train config: ..." for
/// a missing or ill-typed member, and what parse_config throws.
RunSettings settings_from_json(const nlohmann::json& in, const std::filesystem::path& where,
                               const AlgorithmFactory& algorithm);

/// The JSON of the run config at `path` (config.json). Throws std::runtime_error "{what}: no
/// config.json in {folder}" when it cannot be opened, and "{path}: not valid JSON ({the parser's
/// message, with the byte}); ..." or "{path}: not a pixelgym train config: the file holds {type},
/// not an object" when it is corrupt.
nlohmann::json read_run_config(const std::filesystem::path& path, const std::string& what);

/// The settings of `checkpoint` ("config" blob) that differ from `run`'s (config.json's), but
/// the budget (total_env_steps and minutes, which a resume may change): "name: config.json has A,
/// the checkpoint B" joined by "; " (the algorithm's members as "{algorithm}.{member}"); "" when
/// none differs, or when the checkpoint carries no settings (written before they were saved).
std::string settings_differences(const RunSettings& run, const RunSettings& checkpoint);

/// The algorithms a run may use, by AlgorithmFactory::name.
using AlgorithmFactories = std::vector<const AlgorithmFactory*>;

/// The algorithm of config.json's object `in` (read from `where`): the one of `algorithms` whose
/// name is a member of it. Throws std::runtime_error "{where}: not a pixelgym train config: ..."
/// naming the known algorithms when none is.
const AlgorithmFactory& algorithm_of(const nlohmann::json& in, const std::filesystem::path& where,
                                     const AlgorithmFactories& algorithms);

/// The training env: num_envs() copies of the run's env in an AsyncVectorEnv on num_threads
/// threads, SameStep autoreset.
std::unique_ptr<vector::VectorEnv> make_training_env(const RunSettings& settings);

/// One env built as the run's: make(env_id, env_kwargs) under `wraps`.
std::unique_ptr<Env> make_run_env(const RunSettings& settings);

}  // namespace pixelgym::trainer
