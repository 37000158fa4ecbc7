// pixelgym train / eval: the trainer's run (examples/trainer/run) with PPO (examples/trainer/ppo).
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "examples/pixelgym/cli.h"
#include "examples/trainer/ppo/ppo_algorithm.h"
#include "examples/trainer/run/evaluation.h"
#include "examples/trainer/run/process_tuning.h"
#include "examples/trainer/run/training_run.h"

namespace pixelgym::cli {
namespace {

namespace fs = std::filesystem;

// --- train ---

struct TrainArguments : EnvArguments {
  std::string config_file;
  std::int64_t steps = 0;  // 0: the config's total_env_steps
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
  const CLI::App* command = nullptr;  // the parsed subcommand: which flags were given
};

// The settings of a new run: the flags, over the --config file's PPO settings.
trainer::RunSettings new_run_settings(const TrainArguments& args,
                                      const trainer::AlgorithmFactory& algorithm) {
  trainer::RunSettings settings;
  settings.env_id = args.id;
  settings.sets = args.sets;
  settings.wraps = args.wraps;
  std::string config = "{}";
  if (!args.config_file.empty()) {
    std::ifstream in(args.config_file);
    if (!in) throw UsageError("--config " + args.config_file + ": cannot read it");
    std::stringstream text;
    text << in.rdbuf();
    config = text.str();
  }
  settings.algorithm_config = algorithm.parse_config(config);
  if (args.seed_given) settings.algorithm_config["seed"] = args.seed;
  if (args.num_envs > 0) settings.algorithm_config["num_envs"] = args.num_envs;
  settings.num_threads = args.threads;
  settings.torch_threads = args.torch_threads;
  settings.checkpoint_every = args.checkpoint_every;
  settings.keep_checkpoints = args.keep_checkpoints;
  settings.eval_episodes = args.eval_episodes;
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
  return checks;
}

int run_train(const TrainArguments& args) {
  if (args.resume.empty() && args.id.empty()) {
    throw UsageError("train: give an env id, or --resume RUN_FOLDER");
  }
  if (!args.resume.empty() && (!args.id.empty() || !args.sets.empty() || !args.wraps.empty() ||
                               !args.config_file.empty() || !args.out.empty())) {
    throw UsageError(
        "train --resume takes the env and settings from the run's config.json: give no id, "
        "--set, --wrap, --config or --out with it");
  }
  trainer::tune_process_for_training();
  const ppo::PpoAlgorithmFactory ppo;
  const trainer::TrainBudget budget{args.steps, args.minutes};
  const trainer::RunOutput output{std::cout, std::cerr,
                                  trainer::ProgressLine::mode_for_stdout(args.quiet),
                                  trainer::ProgressLine::stdout_columns()};
  try {
    trainer::TrainingRun run =
        args.resume.empty()
            ? trainer::TrainingRun::create(
                  ppo, parse_sets, new_run_settings(args, ppo),
                  args.out.empty() ? fs::path("runs") / args.id : fs::path(args.out), budget,
                  output)
            : trainer::TrainingRun::resume(ppo, parse_sets, args.resume, budget,
                                           resume_checks(args), output);
    run.train();
  } catch (const trainer::RunRequestError& error) {
    throw UsageError(error.what());
  }
  return 0;
}

// What to train and for how long: --config, --steps, --minutes, --out, --resume, --quiet.
void add_run_options(CLI::App& train, TrainArguments& args) {
  train.add_option("--config", args.config_file,
                   "PPO settings as JSON (any subset of the fields; the rest keep their defaults: "
                   "see examples/trainer/ppo/ppo.h, PpoConfig)");
  train.add_option("--steps", args.steps,
                   "Env steps to train for, all envs together; with --set action_repeat=K "
                   "each is K control steps (default: the config's total_env_steps, 1,000,000)");
  train
      .add_option("--minutes", args.minutes,
                  "Stop after this much wall time (then checkpoint, evaluate, write the video); "
                  "with --resume, this much more, and at least one update (without it, a "
                  "resumed run stops when its whole wall time reaches its budget so far)")
      ->check(CLI::Range(0.0, 1e9));
  train.add_option("--out", args.out, "The run folder (default runs/ID); must not hold a run");
  train.add_option("--resume", args.resume,
                   "Continue the run in this folder from its latest valid checkpoint (its "
                   "config.json gives the env and the settings; --steps and --minutes may "
                   "change the budget, and a run setting such as --threads given with it must "
                   "equal the run's). The envs replay the checkpoint's actions and go on "
                   "with their episodes, so with the run's --steps (the learning rate anneals "
                   "over it) the result is the run that did not stop");
  train.add_flag("--quiet", args.quiet,
                 "No progress bar: a plain line every 10 updates (also when stdout is not a "
                 "terminal)");
}

// The run's settings, which a resume checks against the run's: --seed to --eval-episodes.
void add_run_setting_options(CLI::App& train, TrainArguments& args) {
  train
      .add_option("--seed", args.seed,
                  "Seed for torch, the envs and augmentation (default: the config's seed, 0 unless "
                  "--config sets it)")
      ->each([&args](const std::string&) { args.seed_given = true; });
  train
      .add_option(
          "--num-envs", args.num_envs,
          "Envs stepped together (default: the config's num_envs, 8 unless --config sets it)")
      ->check(integer_in(1));
  add_checked_option(train, "--threads", args.threads, "Env threads (AsyncVectorEnv)",
                     integer_in(1));
  add_checked_option(train, "--torch-threads", args.torch_threads,
                     "LibTorch intra-op threads for the forward passes and updates (0: one per "
                     "core this process may run on, or OMP_NUM_THREADS when set); config.json "
                     "records the count used and --resume keeps it",
                     integer_in(0));
  add_checked_option(train, "--keep-checkpoints", args.keep_checkpoints,
                     "The newest checkpoints kept in the run folder, older ones deleted after "
                     "each new one is written (0: keep all; a checkpoint is about 5 MB at the "
                     "demo's settings, written every --checkpoint-every updates)",
                     CLI::Range(std::int64_t{0}, std::int64_t{1} << 40));
  add_checked_option(train, "--checkpoint-every", args.checkpoint_every,
                     "Updates between checkpoints",
                     CLI::Range(std::int64_t{1}, std::int64_t{1} << 40));
  add_checked_option(train, "--eval-episodes", args.eval_episodes,
                     "Seeded episodes of the final evaluation (deterministic actions)",
                     CLI::Range(std::int64_t{1}, std::int64_t{1} << 20));
}

void declare_train(CLI::App& train, TrainArguments& args) {
  args.command = &train;
  train.description(
      "Train a PPO policy from the env's observations (pixels included) and write a run folder: "
      "config.json, progress.csv, curve.png, checkpoints, and at the end final.mp4 and "
      "summary.json (an evaluation over seeded episodes)");
  train.add_option("id", args.id, "Env id, e.g. CartPoleBalance-v0 (`pixelgym list` shows them)");
  add_env_options(train, args);
  add_run_options(train, args);
  add_run_setting_options(train, args);
}

// --- eval ---

struct EvalArguments {
  std::string run;
  std::int64_t episodes = 10;
  std::uint64_t seed = 0;
  std::string video;
  bool stochastic = false;
};

int run_eval(const EvalArguments& args) {
  // RecordVideo names the clip after the path's stem and writes H.264 .mp4 (an .avi given here
  // would come out as .mp4 under another name): refuse any other name before the work.
  if (!args.video.empty() &&
      (fs::path(args.video).extension() != ".mp4" || fs::path(args.video).stem().empty())) {
    throw UsageError("eval --video: expected a FILE.mp4, got \"" + args.video + "\"");
  }
  trainer::tune_process_for_training();
  trainer::EvaluationRequest request{args.episodes, args.seed, args.stochastic, std::nullopt};
  if (!args.video.empty()) request.video = fs::path(args.video);
  const trainer::CheckpointEvaluation result = trainer::evaluate_checkpoint(
      ppo::PpoAlgorithmFactory(), parse_sets, args.run, request, std::cerr);
  const trainer::PolicyEvaluation& evaluation = result.evaluation;
  std::cout << result.checkpoint.string() << ": " << result.settings.env_id << ", " << args.episodes
            << " episodes from seed " << args.seed
            << (args.stochastic ? ", sampled actions" : ", deterministic actions") << "\n";
  for (std::size_t e = 0; e < evaluation.returns.size(); ++e) {
    std::cout << "episode " << e << ": return=" << evaluation.returns[e] << "\n";
  }
  std::cout << "return_mean=" << evaluation.mean << " return_std=" << evaluation.std
            << " clipped_action_fraction=" << evaluation.clipped_fraction << "\n";
  if (request.video) std::cout << "wrote " << request.video->string() << "\n";
  return 0;
}

void declare_eval(CLI::App& eval, EvalArguments& args) {
  eval.description(
      "Evaluate a trained policy (a run folder's latest checkpoint, or a checkpoint "
      "file) over seeded episodes: each return, then their mean and std, and for Box actions "
      "clipped_action_fraction= (the share of action elements the policy put outside the "
      "bounds: near 1 is bang-bang control)");
  eval.add_option("run", args.run, "Run folder or checkpoint file (.pgck)")->required();
  add_checked_option(eval, "--episodes", args.episodes, "Episodes, seeded seed, seed + 1, ...",
                     CLI::Range(std::int64_t{1}, std::int64_t{1} << 20));
  add_seed_option(eval, args.seed, "Seed of the first episode");
  eval.add_option("--video", args.video, "Record the first episode to this .mp4");
  eval.add_flag("--stochastic", args.stochastic,
                "Sample actions from the policy instead of taking its mean / most likely one");
}

}  // namespace

std::vector<Command> add_train_commands(CLI::App& app) {
  return {add_command(app, "train", declare_train, run_train),
          add_command(app, "eval", declare_eval, run_eval)};
}

}  // namespace pixelgym::cli
