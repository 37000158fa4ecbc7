// pixelgym-train's train and eval: the trainer's run (examples/trainer/run) with an algorithm:
// PPO (examples/trainer/ppo) or DrQ-v2 (examples/trainer/drqv2). Only pixelgym-train links it,
// and with it LibTorch.
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "examples/pixelgym/train_commands.h"
#include "examples/trainer/distributed/gloo_communicator.h"
#include "examples/trainer/drq/drq_algorithm.h"
#include "examples/trainer/drqv2/drqv2_algorithm.h"
#include "examples/trainer/ppo/ppo_algorithm.h"
#include "pixelgym/testing/mlp_policy.h"
#include "pixelgym/trainer/atomic_file.h"
#include "pixelgym/trainer/evaluation.h"
#include "pixelgym/trainer/process_tuning.h"
#include "pixelgym/trainer/recipes.h"
#include "pixelgym/trainer/training_run.h"

namespace pixelgym::cli {
namespace {

namespace fs = std::filesystem;

// The algorithms `train --algo` offers, PPO first (the default).
const ppo::PpoAlgorithmFactory kPpo;
const drqv2::DrqV2AlgorithmFactory kDrqV2;
const drq::DrqAlgorithmFactory kDrq;
const trainer::AlgorithmFactories kAlgorithms = {&kPpo, &kDrqV2, &kDrq};

// Set by the first SIGINT (Ctrl-C) during `train`: the run stops at its next step, checkpoints
// and says how to resume; a second SIGINT ends the process at once (the default action).
std::atomic<bool> interrupt_requested{false};

extern "C" void on_interrupt(int) {
  interrupt_requested.store(true);
  ::signal(SIGINT, SIG_DFL);
}

const trainer::AlgorithmFactory& algorithm_named(const std::string& name) {
  for (const trainer::AlgorithmFactory* algorithm : kAlgorithms) {
    if (algorithm->name() == name) return *algorithm;
  }
  throw UsageError("train --algo: unknown algorithm \"" + name + "\"");
}

// The algorithm of the run in `folder` (its config.json names it).
const trainer::AlgorithmFactory& algorithm_of_run(const fs::path& folder) {
  const nlohmann::json config =
      trainer::read_run_config(folder / "config.json", "--resume " + folder.string());
  return trainer::algorithm_of(config, folder / "config.json", kAlgorithms);
}

// This process's command line without --nproc N (or --nproc=N): what each local rank runs.
std::vector<std::string> command_line_without_nproc() {
  std::ifstream file("/proc/self/cmdline", std::ios::binary);
  std::vector<std::string> arguments;
  std::string argument;
  while (std::getline(file, argument, '\0')) arguments.push_back(argument);
  std::vector<std::string> kept;
  for (std::size_t i = 0; i < arguments.size(); ++i) {
    if (arguments[i] == "--nproc") {
      ++i;  // and its value
      continue;
    }
    if (arguments[i].rfind("--nproc=", 0) == 0) continue;
    kept.push_back(arguments[i]);
  }
  return kept;
}

// The flags of this rank's command line that decide the run, as given ({"--num-envs": ["4"],
// "id": [...], ...}): all but --out and --quiet (only rank 0's matter) and --dist-join-timeout
// (each rank's own wait).
nlohmann::json run_flags(const TrainArguments& args) {
  nlohmann::json flags = nlohmann::json::object();
  for (const CLI::Option* option : args.command->get_options()) {
    const std::string name = option->get_name();
    if (option->count() == 0 || name == "--out" || name == "--quiet" ||
        name == "--dist-join-timeout" || name == "--nproc" || name == "--help") {
      continue;
    }
    flags[name] = option->results();
  }
  return flags;
}

// How rank `rank`'s run flags differ from rank 0's ("--num-envs: 3 on rank 1, 2 on rank 0; ..."),
// or "" when they do not.
std::string flag_differences(const nlohmann::json& theirs, int rank, const nlohmann::json& ours) {
  const auto given = [](const nlohmann::json& flags, const std::string& name) {
    if (!flags.contains(name)) return std::string("not given");
    std::string text;
    for (const auto& value : flags.at(name)) {
      text += (text.empty() ? "" : " ") + value.get<std::string>();
    }
    return text;
  };
  std::vector<std::string> names;
  for (const auto& [name, value] : theirs.items()) names.push_back(name);
  for (const auto& [name, value] : ours.items()) {
    if (!theirs.contains(name)) names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  std::string differences;
  for (const std::string& name : names) {
    if (theirs.value(name, nlohmann::json()) == ours.value(name, nlohmann::json())) continue;
    differences += (differences.empty() ? "" : "; ") + name + ": " + given(theirs, name) +
                   " on rank " + std::to_string(rank) + ", " + given(ours, name) + " on rank 0";
  }
  return differences;
}

// Every rank runs rank 0's settings and ignores its own command line, so one that differs from
// rank 0's (but for --out, --quiet, --dist-join-timeout) is refused on every rank before the run
// starts (UsageError naming each flag that differs), rather than ignored without a word.
void check_same_command_line(const TrainArguments& args,
                             distributed::GlooCommunicator& communicator) {
  const nlohmann::json mine = run_flags(args);
  const std::vector<std::string> lines =
      communicator.gather_bytes(mine.dump(), "the ranks' command lines");
  std::vector<std::string> verdicts;
  std::string all;
  if (communicator.rank() == 0) {
    verdicts.emplace_back();
    for (std::size_t r = 1; r < lines.size(); ++r) {
      const std::string differences =
          flag_differences(nlohmann::json::parse(lines[r]), static_cast<int>(r), mine);
      verdicts.push_back(differences);
      if (!differences.empty()) all += (all.empty() ? "" : "; ") + differences;
    }
  }
  const std::string verdict =
      communicator.scatter_bytes(verdicts, "the check of the ranks' command lines");
  // Every rank has its verdict before any stops: rank 0's store may go with it.
  communicator.all_gather(0, "the ranks' command lines read");
  const std::string differences = communicator.rank() == 0 ? all : verdict;
  if (differences.empty()) return;
  throw UsageError("train: rank " + std::to_string(communicator.rank()) +
                   ": the ranks' command lines differ (" + differences +
                   "); every rank runs rank 0's settings, so give every rank the same command "
                   "line (only --out, --quiet and --dist-join-timeout may differ)");
}

std::vector<std::string> algorithm_names() {
  std::vector<std::string> names;
  for (const trainer::AlgorithmFactory* algorithm : kAlgorithms) names.push_back(algorithm->name());
  return names;
}

// The algorithm's config of a new run: --config's (a recipe, a file or inline JSON), then each
// --set-algo over it, each checked by the algorithm as a config file is (UsageError naming the
// option and what the algorithm said).
nlohmann::json algorithm_config(const TrainArguments& args,
                                const trainer::AlgorithmFactory& algorithm) {
  nlohmann::json config = nlohmann::json::object();
  if (!args.config_file.empty()) {
    try {
      const std::string text =
          trainer::config_text(args.config_file, algorithm.name(), algorithm_names());
      algorithm.parse_config(text);  // its errors, before a --set-algo is applied to it
      config = nlohmann::json::parse(text);
    } catch (const std::invalid_argument& error) {
      const std::string message = error.what();
      throw UsageError(message.rfind("--config", 0) == 0
                           ? message
                           : "--config " + args.config_file + ": " + message);
    }
  }
  for (const std::string& set : args.algo_sets) {
    try {
      config = trainer::with_setting(config, set);
      algorithm.parse_config(config.dump());
    } catch (const std::invalid_argument& error) {
      const std::string message = error.what();
      throw UsageError(message.rfind("--set-algo", 0) == 0 ? message
                                                           : "--set-algo " + set + ": " + message);
    }
  }
  return algorithm.parse_config(config.dump());
}

// `train --list-configs`: each recipe of `algorithm` with its settings on one line.
void print_recipes(const trainer::AlgorithmFactory& algorithm) {
  const std::vector<std::string> names = trainer::recipe_names(algorithm.name());
  std::cout << algorithm.name() << " (--algo " << algorithm.name() << "), "
            << trainer::recipe_folder(algorithm.name()).string() << ":\n";
  if (names.empty()) std::cout << "  (none)\n";
  std::size_t width = 0;
  for (const std::string& name : names) width = std::max(width, name.size());
  for (const std::string& name : names) {
    const std::string text = trainer::config_text(name, algorithm.name(), {});
    const nlohmann::json settings = nlohmann::json::parse(text, nullptr, false);
    std::cout << "  " << name << std::string(width - name.size() + 2, ' ')
              << (settings.is_discarded() ? "(not valid JSON)" : settings.dump()) << "\n";
  }
}

// The settings of a new run: the flags, over --set-algo's, over --config's.
trainer::RunSettings new_run_settings(const TrainArguments& args,
                                      const trainer::AlgorithmFactory& algorithm) {
  trainer::RunSettings settings;
  settings.env_id = args.id;
  settings.env_kwargs = parse_sets(args.id, args.sets);  // typed here, at the door
  settings.wraps = args.wraps;
  settings.algorithm = algorithm.name();
  settings.algorithm_config = algorithm_config(args, algorithm);
  if (args.seed_given) settings.algorithm_config["seed"] = args.seed;
  if (args.num_envs > 0) settings.algorithm_config["num_envs"] = args.num_envs;
  settings.num_threads = args.threads;
  settings.torch_threads = args.torch_threads;
  settings.checkpoint_every = args.checkpoint_every;
  settings.keep_checkpoints = args.keep_checkpoints;
  settings.eval_episodes = args.eval_episodes;
  // Ten evaluations over the run unless --eval-every says otherwise.
  const std::int64_t total = args.steps > 0 ? args.steps : settings.total_env_steps();
  settings.eval_every = args.command->count("--eval-every") > 0
                            ? args.eval_every
                            : std::max<std::int64_t>(total / 10, 1);
  settings.eval_every_episodes = args.eval_every_episodes;
  settings.eval_max_share = args.eval_max_share;
  return settings;
}

// The run settings given on the command line, which a resume checks against the run's.
trainer::ResumeChecks resume_checks(const TrainArguments& args) {
  const auto given = [&](const char* flag) { return args.command->count(flag) > 0; };
  trainer::ResumeChecks checks;
  if (args.seed_given) checks.seed = args.seed;
  if (args.num_envs > 0) checks.num_envs = args.num_envs;
  if (given("--threads")) checks.num_threads = args.threads;
  if (given("--torch-threads")) checks.torch_threads = args.torch_threads;
  if (given("--checkpoint-every")) checks.checkpoint_every = args.checkpoint_every;
  if (given("--keep-checkpoints")) checks.keep_checkpoints = args.keep_checkpoints;
  if (given("--eval-episodes")) checks.eval_episodes = args.eval_episodes;
  if (given("--eval-every")) checks.eval_every = args.eval_every;
  if (given("--eval-every-episodes")) checks.eval_every_episodes = args.eval_every_episodes;
  return checks;
}

// `train --list-settings`: each setting of `algorithm` with its default, range and help.
void print_settings(const trainer::AlgorithmFactory& algorithm) {
  std::cout << algorithm.name() << " (--algo " << algorithm.name()
            << "): --config JSON members, or --set-algo NAME=VALUE\n";
  for (const trainer::SettingDescription& setting : algorithm.settings()) {
    std::cout << "  " << setting.name << " = " << setting.value.dump();
    if (!setting.range.empty()) std::cout << "  (" << setting.range << ")";
    std::cout << "\n";
    if (!setting.help.empty()) std::cout << "      " << setting.help << "\n";
  }
  std::cout << "\n";
}

int run_train(const TrainArguments& args) {
  if (args.list_settings) {
    for (const trainer::AlgorithmFactory* algorithm : kAlgorithms) {
      if (!args.algo_given || algorithm->name() == args.algo) print_settings(*algorithm);
    }
    return 0;
  }
  if (args.list_configs) {
    for (const trainer::AlgorithmFactory* algorithm : kAlgorithms) {
      if (!args.algo_given || algorithm->name() == args.algo) print_recipes(*algorithm);
    }
    return 0;
  }
  if (args.resume.empty() && args.id.empty()) {
    throw UsageError("train: give an env id, or --resume RUN_FOLDER");
  }
  if (!args.resume.empty() &&
      (!args.id.empty() || !args.sets.empty() || !args.wraps.empty() || !args.config_file.empty() ||
       !args.algo_sets.empty() || !args.out.empty() || args.algo_given || args.print_config)) {
    throw UsageError(
        "train --resume takes the env and settings from the run's config.json: give no id, "
        "--set, --wrap, --algo, --config, --set-algo, --print-config or --out with it");
  }
  // An unknown id, kwarg or wrapper is refused as `info` refuses it, before any other word (the
  // run's threads warning) and without building the env.
  if (args.resume.empty()) describe_env(args.id, args.sets, args.wraps);
  if (args.print_config) {
    const trainer::AlgorithmFactory& algorithm = algorithm_named(args.algo);
    trainer::RunSettings settings = new_run_settings(args, algorithm);
    if (args.minutes > 0.0) settings.minutes = args.minutes;  // as the run records its budget
    std::cout << trainer::settings_to_json(settings).dump(2) << "\n";
    return 0;
  }
  const bool launcher = args.nproc > 1;
  if (launcher && std::getenv("WORLD_SIZE") != nullptr) {
    throw UsageError(
        "train --nproc starts its own local ranks, but WORLD_SIZE is set (a launcher such as "
        "torchrun or srun started this process as a rank already): give one or the other");
  }
  // A rank of a data-parallel run started by a launcher (torchrun, srun, train --nproc).
  std::optional<distributed::DistributedSettings> ranks;
  if (!launcher) {
    try {
      ranks = distributed::DistributedSettings::from_environment(
          args.dist_timeout, args.dist_join_timeout > 0.0 ? args.dist_join_timeout
                                                          : std::max(args.dist_timeout, 60.0));
    } catch (const std::invalid_argument& error) {
      throw UsageError(error.what());  // WORLD_SIZE, RANK, MASTER_PORT ... not numbers in range
    }
  }
  const bool joins = ranks && ranks->rank > 0;
  // Rank 0 takes the algorithm from the command line or the run folder; the others from it.
  const trainer::AlgorithmFactory& algorithm =
      joins ? kPpo
            : (args.resume.empty() ? algorithm_named(args.algo) : algorithm_of_run(args.resume));
  if ((launcher || (ranks && ranks->world_size > 1)) && algorithm.name() != "ppo") {
    throw UsageError("train --algo " + algorithm.name() +
                     " runs in one process; data-parallel training (--nproc, WORLD_SIZE) is "
                     "PPO's (--algo ppo)");
  }
  if (launcher) {
    return distributed::run_local_ranks(args.nproc, command_line_without_nproc(), args.dist_timeout,
                                        std::cerr);
  }
  trainer::tune_process_for_training();
  // Lines reach a pipe (tee, a log reader) as they are written, not a buffer later.
  std::setvbuf(stdout, nullptr, _IOLBF, BUFSIZ);
  std::unique_ptr<distributed::GlooCommunicator> communicator;
  if (ranks && ranks->world_size > 1) {
    try {
      communicator = std::make_unique<distributed::GlooCommunicator>(*ranks);
    } catch (const std::invalid_argument& error) {
      throw UsageError(error.what());  // RANK given twice, WORLD_SIZE unlike rank 0's ...
    }
    check_same_command_line(args, *communicator);
  }
  const trainer::TrainBudget budget{args.steps, args.minutes};
  // Ranks other than 0 print errors only.
  std::ostream discard(nullptr);
  const trainer::RunOutput output{joins ? discard : std::cout, std::cerr,
                                  trainer::ProgressLine::mode_for_stdout(args.quiet || joins),
                                  trainer::ProgressLine::stdout_columns()};
  if (joins) {
    trainer::TrainingRun::join(kAlgorithms, *communicator, output).train();
    return 0;
  }
  try {
    trainer::TrainingRun run =
        args.resume.empty()
            ? trainer::TrainingRun::create(
                  algorithm, new_run_settings(args, algorithm),
                  args.out.empty() ? fs::path("runs") / args.id : fs::path(args.out), budget,
                  output)
            : trainer::TrainingRun::resume(algorithm, args.resume, budget, resume_checks(args),
                                           output);
    if (communicator) run.distribute(*communicator);
    run.stop_when(interrupt_requested);
    ::signal(SIGINT, on_interrupt);
    run.train();
    ::signal(SIGINT, SIG_DFL);
    if (run.interrupted()) {
      std::cout << "resume with: pixelgym train --resume " << run.folder().string() << std::endl;
      return 130;  // 128 + SIGINT, as a shell reports a process ended by Ctrl-C
    }
  } catch (const trainer::RunRequestError& error) {
    throw UsageError(error.what());
  }
  return 0;
}

int run_eval(const EvalArguments& args) {
  // RecordVideo names the clip after the path's stem and writes H.264 .mp4 (an .avi given here
  // would come out as .mp4 under another name): refuse any other name before the work.
  if (!args.video.empty() &&
      (fs::path(args.video).extension() != ".mp4" || fs::path(args.video).stem().empty())) {
    throw UsageError("eval --video: expected a FILE.mp4, got \"" + args.video + "\"");
  }
  // Before any episode runs: a path that cannot take the video is found now, not after them.
  if (!args.video.empty()) check_video_file("eval --video", args.video);
  trainer::tune_process_for_training();
  trainer::CheckpointEvaluationRequest request;
  if (args.episodes > 0) request.episodes = args.episodes;
  if (args.seed_given) request.seed = args.seed;
  request.stochastic = args.stochastic;
  if (!args.video.empty()) request.video = fs::path(args.video);
  if (!args.env.empty()) request.env_id = args.env;
  request.env_sets = args.sets;
  const trainer::CheckpointEvaluation result =
      trainer::evaluate_checkpoint(kAlgorithms, args.run, request, std::cerr);
  const trainer::PolicyEvaluation& evaluation = result.evaluation;
  const std::string from =
      args.seed_given && args.episodes > 0 ? "" : " (as " + result.defaults_from + ")";
  std::cout << result.checkpoint.string() << ": " << result.settings.env_id << ", "
            << result.request.episodes << " episodes from seed " << result.request.seed << from
            << (args.stochastic ? ", sampled actions" : ", deterministic actions") << "\n";
  for (std::size_t e = 0; e < evaluation.returns.size(); ++e) {
    std::cout << "episode " << e << ": return=" << evaluation.returns[e] << "\n";
  }
  std::cout << "return_mean=" << evaluation.mean << " return_std=" << evaluation.std
            << " clipped_action_fraction=" << evaluation.clipped_fraction << "\n";
  if (request.video) std::cout << "wrote " << request.video->string() << "\n";
  return 0;
}

int run_export(const ExportArguments& args) {
  const fs::path out(args.out);
  const fs::path folder = out.parent_path().empty() ? fs::path(".") : out.parent_path();
  if (!fs::is_directory(folder)) {
    throw UsageError("export --out: expected a file in an existing folder, got \"" + args.out +
                     "\" (" + folder.string() + " is not a folder)");
  }
  trainer::CheckpointPolicy policy =
      trainer::load_checkpoint_policy(kAlgorithms, args.run, "export", std::cerr);
  const trainer::RunSettings& settings = policy.settings;
  nlohmann::json file;
  try {
    file = policy.actor->mlp_policy();
  } catch (const std::invalid_argument& error) {
    throw std::runtime_error("export: " + policy.checkpoint.string() + " (" + settings.algorithm +
                             " on " + settings.env_id + "): " + error.what());
  }
  if (!settings.wraps.empty()) {
    throw std::runtime_error("export: " + policy.checkpoint.string() +
                             ": expected a run on the bare env (a policy file names the env by its "
                             "id and kwargs), got one wrapped in --wrap " +
                             settings.wraps.front());
  }
  file["env_id"] = settings.env_id;
  file["env_kwargs"] = trainer::settings_to_json(settings).at("env_kwargs");
  file["source"] = {{"checkpoint", policy.checkpoint.filename().string()},
                    {"algorithm", settings.algorithm},
                    {"env_steps", policy.env_steps},
                    {"seed", settings.seed()}};
  const std::string text = file.dump(1) + "\n";
  // What is written reads back: a policy MlpPolicy refuses is refused here, and no file written.
  try {
    testing::MlpPolicy::parse(text, out.string());
  } catch (const std::runtime_error& error) {
    throw std::runtime_error("export: " + policy.checkpoint.string() +
                             ": the policy file would not load: " + error.what());
  }
  trainer::write_file_atomically(out, {text}, "export");
  std::cout << "wrote " << out.string() << " (" << settings.env_id << ", "
            << file.at("layers").size() << " layers, from " << policy.checkpoint.string() << " at "
            << policy.env_steps << " env steps)\n";
  return 0;
}

}  // namespace

Trainer in_process_trainer() { return {run_train, run_eval, run_export}; }

}  // namespace pixelgym::cli
