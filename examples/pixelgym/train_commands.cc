// pixelgym train, eval, export and compare: their command lines (train_commands.h), and compare,
// which draws finished runs' curves; train, eval and export run in pixelgym-train (trainer.cc).
#include "examples/pixelgym/train_commands.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/render/image_io.h"
#include "pixelgym/trainer/atomic_file.h"
#include "pixelgym/trainer/curve_plot.h"
#include "pixelgym/trainer/progress_csv.h"
#include "pixelgym/trainer/training_run.h"

namespace pixelgym::cli {
namespace {

namespace fs = std::filesystem;

// --- train ---

// What to train and for how long: --config, --steps, --minutes, --out, --resume, --quiet.
void add_run_options(CLI::App& train, TrainArguments& args) {
  train
      .add_option("--algo", args.algo,
                  "The learning algorithm: ppo (PPO, on-policy; the default), drq (DrQ: "
                  "off-policy soft actor-critic with a squashed Gaussian policy, clipped double "
                  "Q, a learned entropy temperature and random-shift augmentation; from the "
                  "joint state it is SAC) or drqv2 (DrQ-v2: off-policy DDPG with a twin critic, "
                  "n-step returns from a replay buffer, random-shift augmentation and scheduled "
                  "exploration noise). drq and drqv2 take Box actions only, and images as --wrap "
                  "frame_stack=3 stacks. The run's config.json names it; "
                  "--resume and eval read it from there")
      ->check(name_in({"ppo", "drqv2", "drq"}, "algorithm"))
      ->each([&args](const std::string&) { args.algo_given = true; });
  train.add_option(
      "--config", args.config_file,
      "The algorithm's settings as JSON (any subset of the fields; the rest keep "
      "their defaults): a recipe's name (e.g. swingup: the configs installed with the tool for "
      "--algo's algorithm, which --list-configs shows), a FILE.json (or any path with a '/'), or "
      "the JSON itself, e.g. "
      "'{\"gamma\": 0.95}'. --print-config shows every field of --algo's algorithm with the "
      "value a run would use, --list-settings every setting of each algorithm (its default, "
      "its range and what it does), --list-configs the recipes");
  train
      .add_option("--set-algo", args.algo_sets,
                  "One of the algorithm's settings as KEY=VALUE (repeatable), over --config's: "
                  "--set-algo gamma=0.95, --set-algo policy.cnn=fine for a member of an object "
                  "member. VALUE is JSON (0.95, true, [64,64]) or else a word (fine); an unknown "
                  "KEY or a VALUE of the wrong type is refused as in a config file")
      ->type_name("KEY=VALUE");
  train.add_flag("--list-configs", args.list_configs,
                 "Print the recipes that --config NAME takes (of --algo's algorithm when given, "
                 "else of each), each with its settings, and exit");
  train.add_flag("--list-settings", args.list_settings,
                 "Print every setting that --config and --set-algo take (of --algo's algorithm "
                 "when given, else of each): its name, default, range and what it does, and exit");
  train.add_flag("--print-config", args.print_config,
                 "Print the settings the run would write to config.json (--config, --set-algo "
                 "and the flags applied) and exit without training or writing anything");
  train.add_option("--steps", args.steps,
                   "Env steps to train for, all envs together; with --set action_repeat=K "
                   "each is K control steps (default: the config's total_env_steps: ppo "
                   "1,000,000, drq and drqv2 100,000)");
  train
      .add_option("--minutes", args.minutes,
                  "Stop after this much wall time (0, the default: no time limit), the final "
                  "checkpoint, evaluation and video included: training stops within an update when "
                  "the time left is what the "
                  "final evaluation needs (at most a quarter of it: fewer --eval-episodes, or "
                  "no video, when they do not fit; said in a line and in summary.json); with "
                  "--resume, this much more, and at least one update (without it, a resumed "
                  "run stops when its whole wall time reaches its budget so far)")
      ->check(CLI::Range(0.0, 1e9));
  train.add_option("--out", args.out, "The run folder (default runs/ID); must not hold a run");
  train.add_option("--resume", args.resume,
                   "Continue the run in this folder from its latest valid checkpoint (its "
                   "config.json gives the env and the settings; --steps and --minutes may "
                   "change the budget, and a run setting such as --threads given with it must "
                   "equal the run's). The envs replay the checkpoint's actions and go on "
                   "with their episodes, so with the run's --steps (the learning rate anneals "
                   "over it) the result is the run that did not stop. drq's and drqv2's replay "
                   "buffers are not in the checkpoints: the replayed actions refill them with "
                   "the same transitions");
  add_checked_option(
      train, "--nproc", args.nproc,
      "Train data-parallel (DD-PPO) with this many local processes (ranks), as torchrun "
      "--standalone would start them: each steps its own --num-envs envs (rank r's env i is "
      "seeded seed + r * num_envs + i) and gradients are averaged across ranks after every "
      "minibatch, so all hold the same parameters; rank 0 writes the run folder and "
      "progress.csv counts every rank's env steps. Each rank gets OMP_NUM_THREADS = cores / N "
      "unless it is set. Across machines, start `pixelgym train` (no --nproc) once per rank "
      "with MASTER_ADDR, MASTER_PORT, WORLD_SIZE and RANK set (torchrun and srun set them). "
      "ppo only; --resume needs the run's own count",
      CLI::Range(1, 1024));
  add_checked_option(train, "--dist-timeout", args.dist_timeout,
                     "Seconds a rank of a data-parallel run may stop answering (its heartbeat "
                     "stands still: it died, was stopped or hangs) before the others stop with "
                     "an error naming it",
                     CLI::Range(1.0, 86400.0));
  train
      .add_option("--dist-join-timeout", args.dist_join_timeout,
                  "Seconds every rank of a data-parallel run has to start and join the others "
                  "at rank 0's store before the ranks that came stop with an error naming those "
                  "missing (default: --dist-timeout, at least 60)")
      ->check(CLI::Range(1.0, 86400.0));
  train.add_flag("--quiet", args.quiet,
                 "No progress bar: a plain line every 10 updates, and at least every 10 s (also "
                 "when stdout is not a terminal)");
}

// The run's settings, which a resume checks against the run's: --seed to --eval-episodes.
void add_run_setting_options(CLI::App& train, TrainArguments& args) {
  add_seed_option(train, args.seed,
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
                     "core this process may run on, as PyTorch, or OMP_NUM_THREADS when set; a "
                     "warning when that is more than the cores the machine's load leaves "
                     "free); config.json records the count used and --resume keeps it",
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
  // No default shown: it follows --steps.
  train
      .add_option("--eval-every", args.eval_every,
                  "Evaluate the policy during training each time the env steps pass a "
                  "multiple of this (default: a tenth of --steps, ten evaluations; 0: never), "
                  "over --eval-every-episodes deterministic episodes with the final "
                  "evaluation's seeds; each adds a row to eval.csv (steps, wall_time_s, "
                  "return_mean, return_std, episodes, eval_s). An evaluation is skipped while "
                  "this process's evaluations have taken more than --eval-max-share of its "
                  "wall time")
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{1} << 50));
  add_checked_option(train, "--eval-every-episodes", args.eval_every_episodes,
                     "Episodes of each evaluation during training",
                     CLI::Range(std::int64_t{1}, std::int64_t{1} << 20));
  add_checked_option(train, "--eval-max-share", args.eval_max_share,
                     "The share of this process's wall time that evaluations during training may "
                     "take before the next is skipped (1: never skipped); config.json keeps it",
                     CLI::Range(0.001, 1.0));
}

void declare_train(CLI::App& train, TrainArguments& args) {
  args.command = &train;
  train.description(
      "Train a policy (PPO; DrQ with --algo drq, DrQ-v2 with --algo drqv2) from the env's "
      "observations (pixels "
      "included) and write a run folder: "
      "config.json, progress.csv, eval.csv, curve.png, checkpoints, and at the end final.mp4 and "
      "summary.json (an evaluation over seeded episodes)");
  train.add_option("id", args.id, "Env id, e.g. CartPoleBalance-v1 (`pixelgym list` shows them)");
  add_env_options(train, args);
  add_run_options(train, args);
  add_run_setting_options(train, args);
}

// --- eval ---

void declare_eval(CLI::App& eval, EvalArguments& args) {
  eval.description(
      "Evaluate a trained policy (a run folder's latest checkpoint, or a checkpoint "
      "file) over seeded episodes: each return, then their mean and std, and for Box actions "
      "clipped_action_fraction= (the share of action elements the policy put outside the "
      "bounds: near 1 is bang-bang control)");
  eval.add_option("run", args.run, "Run folder or checkpoint file (.pgck)")->required();
  eval.add_option("--episodes", args.episodes,
                  "Episodes, seeded seed, seed + 1, ... (default: as the run's final evaluation, "
                  "summary.json's: --eval-episodes)")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 20));
  add_seed_option(eval, args.seed,
                  "Seed of the first episode (default: as the run's final evaluation, "
                  "summary.json's: the run's --seed + 1000000, so that the returns agree with "
                  "it)")
      ->default_str("")  // the run's, not 0
      ->each([&args](const std::string&) { args.seed_given = true; });
  eval.add_option("--video", args.video, "Record the first episode to this .mp4");
  eval.add_flag("--stochastic", args.stochastic,
                "Sample actions from the policy instead of taking its mean / most likely one");
  eval.add_option("--env", args.env,
                  "Play in this env instead of the run's, with the run's kwargs and --wrap (its "
                  "spaces must be the run's): e.g. the task's -distracting variant, to see how a "
                  "policy trained on the plain task copes with distractions");
  eval.add_option("--set", args.sets,
                  "Env kwarg as key=value over the run's (repeatable), e.g. variation=0.3")
      ->type_name("KEY=VALUE");
}

// --- export ---

void declare_export(CLI::App& command, ExportArguments& args) {
  command.description(
      "Write a trained policy (a run folder's latest checkpoint, or a checkpoint file) as a "
      "policy file that runs without LibTorch: JSON with the env id and kwargs, the observation "
      "keys it reads and its layers' weights (pixelgym::testing::MlpPolicy loads and runs it). "
      "For policies that are an MLP over vector observations: a drq run trained from state "
      "(--set obs_mode=state)");
  command.add_option("run", args.run, "Run folder or checkpoint file (.pgck)")->required();
  command.add_option("--out", args.out, "The policy file to write (JSON)")->required();
}

// --- compare ---

struct CompareArguments {
  std::vector<std::string> runs;
  std::string out;
  std::string curve = "eval";
  bool curve_given = false;
  std::string title;
  int width = 1100;
  int height = 500;
};

// The control steps per env step of a run: its env kwarg action_repeat (1 without); a run
// config written before the kwargs were kept typed has it as "set": ["action_repeat=K"].
double action_repeat_of(const nlohmann::json& config) {
  const auto kwargs = config.find("env_kwargs");
  if (kwargs != config.end() && kwargs->is_object()) {
    const auto repeat = kwargs->find("action_repeat");
    return repeat != kwargs->end() && repeat->is_number() ? repeat->get<double>() : 1.0;
  }
  double repeat = 1.0;
  for (const auto& set : config.value("set", std::vector<std::string>{})) {
    const std::string key = "action_repeat=";
    if (set.rfind(key, 0) == 0) repeat = std::stod(set.substr(key.size()));
  }
  return repeat;
}

// The folder of a compare argument (FOLDER or FOLDER=LABEL).
fs::path compared_folder(const std::string& spec) { return spec.substr(0, spec.find('=')); }

int run_compare(const CompareArguments& given) {
  CompareArguments args = given;
  // Every run must have the curve asked for, found before the table starts: runs stopped by
  // --minutes before their first evaluation have no eval.csv.
  if (args.curve == "eval") {
    for (const std::string& spec : args.runs) {
      const fs::path file = compared_folder(spec) / "eval.csv";
      if (fs::exists(file)) continue;
      if (args.curve_given) {
        throw UsageError("compare --curve eval: " + file.string() +
                         " does not exist (the run made no evaluation during training: "
                         "--eval-every 0, or its budget ended before the first); its training "
                         "returns are in progress.csv: --curve train draws those");
      }
      std::cerr << "compare: " << compared_folder(spec).string()
                << " has no eval.csv (no evaluation during training: --eval-every 0, or its "
                   "budget ended before the first), so every run's training returns are drawn "
                   "(--curve train)\n";
      args.curve = "train";
      break;
    }
  }
  std::vector<trainer::ComparedCurve> curves;
  std::cout << "run,control_steps,wall_minutes,return_mean,return_std\n";
  for (const std::string& spec : args.runs) {
    const std::size_t equals = spec.find('=');
    const fs::path folder = spec.substr(0, equals);
    trainer::ComparedCurve curve;
    curve.label =
        equals == std::string::npos ? folder.filename().string() : spec.substr(equals + 1);
    std::ifstream config_file(folder / "config.json");
    if (!config_file) throw UsageError("compare: " + folder.string() + " has no config.json");
    const double repeat = action_repeat_of(nlohmann::json::parse(config_file));
    if (args.curve == "eval") {
      const fs::path file = folder / "eval.csv";
      if (!fs::exists(file)) {
        throw UsageError("compare: " + file.string() +
                         " does not exist (a run without evaluations during training; "
                         "--curve train plots its training returns)");
      }
      for (const trainer::EvalRow& row :
           trainer::parse_eval_csv(trainer::read_whole_file(file, "compare"), file.string())) {
        curve.x.push_back(static_cast<double>(row.steps) * repeat);
        curve.wall_minutes.push_back(row.wall_time_s / 60.0);
        curve.mean.push_back(row.return_mean);
        curve.std.push_back(row.return_std);
      }
    } else {
      const trainer::ProgressTable table = trainer::read_progress_csv(folder / "progress.csv");
      for (const double steps : table.column("steps")) curve.x.push_back(steps * repeat);
      for (const double seconds : table.column("wall_time_s")) {
        curve.wall_minutes.push_back(seconds / 60.0);
      }
      curve.mean = table.column("episode_return_mean");
      curve.std = table.column("episode_return_std");
    }
    if (!curve.x.empty()) {
      std::cout << curve.label << "," << curve.x.back() << "," << curve.wall_minutes.back() << ","
                << curve.mean.back() << "," << curve.std.back() << "\n";
    }
    curves.push_back(std::move(curve));
  }
  trainer::CurvePlotOptions options;
  options.title = args.title.empty()
                      ? (args.curve == "eval" ? "evaluation return" : "training return")
                      : args.title;
  options.width = args.width;
  options.height = args.height;
  options.x_label = "control steps (env steps x action_repeat)";
  const render::Image image = trainer::draw_comparison(curves, options);
  render::write_png(args.out, image.view());
  std::cout << "wrote " << args.out << "\n";
  return 0;
}

void declare_compare(CLI::App& compare, CompareArguments& args) {
  compare.description(
      "Draw the learning curves of several run folders side by side into a PNG: return against "
      "control steps (env steps times the run's --set action_repeat) and against wall minutes; "
      "print each run's last point as CSV");
  compare.add_option("runs", args.runs, "Run folders, each optionally FOLDER=LABEL")->required();
  compare.add_option("--out", args.out, "The PNG to write")->required();
  compare
      .add_option("--curve", args.curve,
                  "eval: the evaluations during training (eval.csv: deterministic episodes; by "
                  "default, and when a run has none, every run's training returns instead, "
                  "said on stderr); train: the training episodes' returns (progress.csv)")
      ->check(CLI::IsMember({"eval", "train"}))
      ->each([&args](const std::string&) { args.curve_given = true; });
  compare.add_option("--title", args.title, "The plot's title");
  add_checked_option(compare, "--width", args.width, "Width in pixels", CLI::Range(400, 8000));
  add_checked_option(compare, "--height", args.height, "Height in pixels", CLI::Range(250, 8000));
}

}  // namespace

Trainer exec_trainer(char** argv) {
  const auto replace_this_process = [argv]() -> int {
    std::error_code error;
    const fs::path self = fs::read_symlink("/proc/self/exe", error);
    const fs::path program = (error ? fs::path(argv[0]) : self).parent_path() / "pixelgym-train";
    std::cout.flush();
    std::cerr.flush();
    ::execv(program.c_str(), argv);
    throw std::runtime_error(
        "cannot start " + program.string() + ": " + std::strerror(errno) +
        " (pixelgym runs train, eval and export in pixelgym-train, the program "
        "beside it that links LibTorch)");
  };
  return {[replace_this_process](const TrainArguments&) { return replace_this_process(); },
          [replace_this_process](const EvalArguments&) { return replace_this_process(); },
          [replace_this_process](const ExportArguments&) { return replace_this_process(); }};
}

std::vector<Command> add_train_commands(CLI::App& app, const Trainer& trainer) {
  return {add_command(app, "train", declare_train, trainer.train),
          add_command(app, "eval", declare_eval, trainer.eval),
          add_command(app, "export", declare_export, trainer.export_policy),
          add_command(app, "compare", declare_compare, run_compare)};
}

}  // namespace pixelgym::cli
