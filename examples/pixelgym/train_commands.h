// pixelgym train, eval and export: their command lines, and what runs them. LibTorch is loaded only
// by pixelgym-train, the program that runs them (trainer.cc); pixelgym parses their command lines
// and then replaces itself by it, so that its other subcommands start without LibTorch (0.9 s of
// every start otherwise).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "examples/pixelgym/cli.h"

namespace pixelgym::cli {

/// `pixelgym train`'s command line.
struct TrainArguments : EnvArguments {
  std::string algo = "ppo";
  bool algo_given = false;
  std::string config_file;             // --config: a recipe's name, a file or inline JSON
  std::vector<std::string> algo_sets;  // --set-algo KEY=VALUE, over --config
  bool list_configs = false;           // --list-configs: print the recipes, train nothing
  bool list_settings = false;          // --list-settings: print the settings, train nothing
  bool print_config = false;           // --print-config: print the settings, train nothing
  std::int64_t steps = 0;              // 0: the config's total_env_steps
  double minutes = 0.0;
  std::string out;
  std::string resume;
  bool quiet = false;
  std::uint64_t seed = 0;
  bool seed_given = false;
  int num_envs = 0;
  int threads = 2;
  int torch_threads = 0;
  std::int64_t checkpoint_every = 10;
  std::int64_t keep_checkpoints = 3;
  std::int64_t eval_episodes = 5;
  std::int64_t eval_every = 0;
  std::int64_t eval_every_episodes = 5;
  double eval_max_share = 0.1;
  int nproc = 1;
  double dist_timeout = 60.0;
  double dist_join_timeout = 0.0;     // 0: max(dist_timeout, 60)
  const CLI::App* command = nullptr;  // the parsed subcommand: which flags were given
};

/// `pixelgym eval`'s command line.
struct EvalArguments {
  std::string run;
  std::int64_t episodes = 0;  // 0: the run's final evaluation's (summary.json's)
  std::uint64_t seed = 0;
  bool seed_given = false;  // else the run's final evaluation's seed (summary.json's)
  std::string video;
  bool stochastic = false;
  std::string env;                // --env: another env to play in (same spaces); empty: the run's
  std::vector<std::string> sets;  // --set KEY=VALUE, over the run's env kwargs
};

/// `pixelgym export`'s command line.
struct ExportArguments {
  std::string run;
  std::string out;
};

/// What runs train, eval and export once their command lines parsed (each returns the exit
/// code).
struct Trainer {
  std::function<int(const TrainArguments&)> train;
  std::function<int(const EvalArguments&)> eval;
  std::function<int(const ExportArguments&)> export_policy;
};

/// pixelgym-train's: trains and evaluates in this process, with LibTorch (trainer.cc).
Trainer in_process_trainer();

/// pixelgym's: replaces this process by pixelgym-train, the program in this executable's folder,
/// with `argv` (the same command line; the same process id). Throws std::runtime_error naming
/// the program and the OS's reason when it cannot be started.
Trainer exec_trainer(char** argv);

/// Adds train, eval, export and compare to `app`; train, eval and export run through `trainer`.
std::vector<Command> add_train_commands(CLI::App& app, const Trainer& trainer);

}  // namespace pixelgym::cli
