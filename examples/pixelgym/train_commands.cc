// pixelgym train / eval: PPO from pixels (examples/ppo) with a run folder (examples/ppo/run).
#include <sched.h>
#include <torch/torch.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "envs/registry.h"
#include "envs/vector/make_vec.h"
#include "envs/vector/sync_vector_env.h"
#include "examples/pixelgym/cli.h"
#include "examples/ppo/policy.h"
#include "examples/ppo/ppo.h"
#include "examples/ppo/run/checkpoint_file.h"
#include "examples/ppo/run/process_tuning.h"
#include "examples/ppo/run/progress_line.h"
#include "examples/ppo/run/run_folder.h"
#include "wrappers/record_video.h"
#include "wrappers/wrapper_spec.h"

namespace pixelgym::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// LibTorch's intra-op threads (the convolutions and matrix products of the updates and forward
// passes): `requested`, or when 0 one per core this process may run on. LibTorch's own default is
// OpenMP's, which is not always the core count: on a 2-core Debian 12 VM it was 1, and the
// updates ran on one core (a 64x64 9-channel minibatch of 128 through the small CNN, forward and
// backward: 78 ms with 1 thread, 46 ms with 2; bench/train_throughput.sh on the demo's settings:
// 209 against 322 env steps/s).
// OMP_NUM_THREADS, when the user set it, wins over the default (not over `requested`). Returns
// the count in use.
int set_torch_threads(int requested) {
  if (requested == 0 && std::getenv("OMP_NUM_THREADS") != nullptr) return torch::get_num_threads();
  int threads = requested;
  if (threads == 0) {
    cpu_set_t cpus;
    CPU_ZERO(&cpus);
    threads = sched_getaffinity(0, sizeof(cpus), &cpus) == 0 ? CPU_COUNT(&cpus) : 1;
  }
  torch::set_num_threads(std::max(threads, 1));
  return torch::get_num_threads();
}

// Episodes whose returns the progress rows summarize (as Stable-Baselines3's ep_info_buffer).
constexpr std::size_t kReturnWindow = 100;

// What a run is: the env and how the trainer is set up. Written to config.json; `eval` and
// `--resume` read it back.
struct RunSettings {
  std::string id;
  std::vector<std::string> sets;  // KEY=VALUE, as --set takes them
  std::vector<std::string> wraps;
  int num_threads = 2;
  int torch_threads = 0;               // LibTorch intra-op threads (see set_torch_threads)
  std::int64_t checkpoint_every = 10;  // updates
  std::int64_t keep_checkpoints = 3;   // the newest kept, 0: all
  double minutes = 0.0;                // 0: no time limit
  std::int64_t eval_episodes = 5;
  ppo::PpoConfig ppo;
};

json settings_to_json(const RunSettings& settings) {
  json out;
  out["env_id"] = settings.id;
  out["set"] = settings.sets;
  out["wrap"] = settings.wraps;
  out["num_threads"] = settings.num_threads;
  out["torch_threads"] = settings.torch_threads;
  out["checkpoint_every"] = settings.checkpoint_every;
  out["keep_checkpoints"] = settings.keep_checkpoints;
  out["minutes"] = settings.minutes;
  out["eval_episodes"] = settings.eval_episodes;
  out["ppo"] = json::parse(ppo::config_to_json(settings.ppo));
  return out;
}

RunSettings settings_from_json(const json& in, const fs::path& where) {
  try {
    RunSettings settings;
    settings.id = in.at("env_id").get<std::string>();
    settings.sets = in.at("set").get<std::vector<std::string>>();
    settings.wraps = in.at("wrap").get<std::vector<std::string>>();
    settings.num_threads = in.at("num_threads").get<int>();
    // Run folders from before the field: 0, the default count.
    settings.torch_threads = in.value("torch_threads", 0);
    settings.checkpoint_every = in.at("checkpoint_every").get<std::int64_t>();
    // Run folders from before the field kept every checkpoint, and go on doing so.
    settings.keep_checkpoints = in.value("keep_checkpoints", std::int64_t{0});
    settings.minutes = in.at("minutes").get<double>();
    settings.eval_episodes = in.at("eval_episodes").get<std::int64_t>();
    settings.ppo = ppo::config_from_json(in.at("ppo").dump());
    return settings;
  } catch (const json::exception& e) {
    throw std::runtime_error(where.string() + ": not a pixelgym train config: " + e.what());
  }
}

// progress.csv's columns after the base ones: more of the update's figures, and where the
// update's time went: env_s in the vector env's step/reset, act_s in the policy's forward passes
// while collecting, update_s in the PPO epochs.
const std::vector<std::string> kExtraColumns = {
    "explained_variance", "grad_norm", "learning_rate", "env_s", "act_s", "update_s"};

// The training env: num_envs copies, SameStep autoreset (the trainer bootstraps truncated
// steps from infos["final_obs"]).
std::unique_ptr<vector::VectorEnv> make_training_env(const RunSettings& settings) {
  const vector::VectorOptions options{vector::VectorMode::kAsync, settings.num_threads,
                                      vector::AutoresetMode::kSameStep, true};
  return vector::make_vec(settings.id, static_cast<int>(settings.ppo.num_envs),
                          parse_sets(settings.id, settings.sets),
                          wrappers::wrapping(settings.wraps), options);
}

std::string to_bytes(const std::function<void(std::ostream&)>& save) {
  std::ostringstream out(std::ios::binary);
  save(out);
  return out.str();
}

// The checkpoint of `trainer` after its latest update: model, optimizer, generators, progress.
ppo::CheckpointBlobs checkpoint_blobs(const RunSettings& settings, ppo::Trainer& trainer,
                                      const std::deque<double>& returns, double wall_time_s) {
  ppo::CheckpointBlobs blobs;
  // The run's settings, so that a checkpoint file evaluates on its own (away from its folder).
  blobs["config"] = settings_to_json(settings).dump();
  blobs["model"] = to_bytes([&](std::ostream& out) { torch::save(trainer.policy_ptr(), out); });
  blobs["optimizer"] = to_bytes([&](std::ostream& out) { torch::save(trainer.optimizer(), out); });
  const ppo::TrainerRngState rng = trainer.rng_state();
  blobs["rng_sampling"] = to_bytes([&](std::ostream& out) { torch::save(rng.sampling, out); });
  blobs["rng_augmentation"] =
      to_bytes([&](std::ostream& out) { torch::save(rng.augmentation, out); });
  json meta;
  meta["env_steps"] = trainer.env_steps();
  meta["updates"] = trainer.updates();
  meta["wall_time_s"] = wall_time_s;
  meta["recent_returns"] = std::vector<double>(returns.begin(), returns.end());
  const ppo::RewardScaling& scaling = trainer.reward_scaling();
  // JSON numbers keep a double exactly (17 significant digits).
  meta["reward_scaling"] = {{"mean", scaling.statistics.mean[0]},
                            {"var", scaling.statistics.var[0]},
                            {"count", scaling.statistics.count},
                            {"returns", scaling.returns}};
  // Where the envs are, for a resume to check its replay of the actions below against.
  meta["env_digest"] = trainer.env_digest();
  blobs["meta"] = meta.dump();
  // The envs' state, as the actions that led to it (see Trainer::replay_env); none when the log
  // does not go back to the first reset (a run resumed from a checkpoint without actions).
  if (trainer.env_action_log_complete()) blobs["env_actions"] = trainer.env_action_log();
  return blobs;
}

template <typename T>
void load_blob(const ppo::CheckpointBlobs& blobs, const std::string& name, T& into,
               const fs::path& path) {
  const auto found = blobs.find(name);
  if (found == blobs.end()) {
    throw std::runtime_error(path.string() + ": the checkpoint has no \"" + name + "\" entry");
  }
  std::istringstream in(found->second, std::ios::binary);
  torch::load(into, in);
}

json read_meta(const ppo::CheckpointBlobs& blobs, const fs::path& path) {
  const auto found = blobs.find("meta");
  if (found == blobs.end()) {
    throw std::runtime_error(path.string() + ": the checkpoint has no \"meta\" entry");
  }
  return json::parse(found->second);
}

struct Evaluation {
  double mean = 0.0;
  double std = 0.0;
  std::vector<double> returns;
  // Box actions: the fraction of action elements the policy put outside the bounds (sent to
  // the env clipped). Near 1, the policy acts bang-bang at the bounds; 0 for Discrete.
  double clipped_fraction = 0.0;
};

// `episodes` episodes of `policy` on one env built as the run's (env i seeded seed + i), with
// deterministic (mean / argmax) actions unless `stochastic`; the first recorded to `video`
// when given.
Evaluation evaluate(ppo::Policy& policy, const RunSettings& settings, std::int64_t episodes,
                    std::uint64_t seed, bool stochastic, const std::optional<fs::path>& video) {
  wrappers::RecordVideo* recorder = nullptr;
  const vector::EnvFactory factory = [&](int) {
    std::unique_ptr<Env> env = wrappers::apply_wrappers(
        make(settings.id, parse_sets(settings.id, settings.sets)), settings.wraps);
    if (!video) return env;
    const fs::path folder = video->parent_path().empty() ? fs::path(".") : video->parent_path();
    auto recorded = std::make_unique<wrappers::RecordVideo>(
        std::move(env), folder, [](std::int64_t) { return false; }, nullptr, 0, "eval");
    recorder = recorded.get();
    return std::unique_ptr<Env>(std::move(recorded));
  };
  vector::SyncVectorEnv env(1, factory, vector::AutoresetMode::kDisabled);
  torch::NoGradGuard no_grad;
  Value actions = env.action_space().zeros();
  Array& action = actions.array();
  Evaluation result;
  double clipped = 0.0;
  double elements = 0.0;
  for (std::int64_t e = 0; e < episodes; ++e) {
    if (e == 0 && recorder != nullptr) recorder->start_recording(video->stem().string());
    const Value* obs = &env.reset(seed + static_cast<std::uint64_t>(e)).obs;
    double total = 0.0;
    for (;;) {
      const ppo::ActResult act = policy.act(ppo::observation_tensors(*obs), !stochastic);
      const torch::Tensor chosen = act.env_action.to(ppo::torch_dtype(action.dtype())).contiguous();
      if (act.action.is_floating_point()) {
        clipped += static_cast<double>(act.clipped_elements());
        elements += static_cast<double>(act.action.numel());
      }
      std::memcpy(action.raw_data(), chosen.data_ptr(), action.nbytes());
      const vector::VectorStepResult& step = env.step(actions);
      total += step.rewards.data<double>()[0];
      obs = &step.obs;
      if (step.terminated.data<bool>()[0] || step.truncated.data<bool>()[0]) break;
    }
    if (e == 0 && recorder != nullptr) recorder->stop_recording();
    result.returns.push_back(total);
  }
  double sum = 0.0;
  for (const double r : result.returns) sum += r;
  result.mean = sum / static_cast<double>(result.returns.size());
  double squares = 0.0;
  for (const double r : result.returns) squares += (r - result.mean) * (r - result.mean);
  result.std = std::sqrt(squares / static_cast<double>(result.returns.size()));
  if (elements > 0.0) result.clipped_fraction = clipped / elements;
  env.close();
  return result;
}

json evaluation_json(const Evaluation& evaluation, std::uint64_t seed, bool stochastic) {
  json out;
  out["episodes"] = evaluation.returns.size();
  out["seed"] = seed;
  out["deterministic"] = !stochastic;
  out["return_mean"] = evaluation.mean;
  out["return_std"] = evaluation.std;
  out["returns"] = evaluation.returns;
  out["clipped_action_fraction"] = evaluation.clipped_fraction;
  return out;
}

// --- train ---

struct TrainArguments {
  std::string id;
  std::vector<std::string> sets;
  std::vector<std::string> wraps;
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
  std::vector<std::string> given;  // which of the run settings' flags were on the command line
};

// With --resume the run's own settings hold; a flag that asks for another value is refused
// (naming both) rather than silently ignored. The same value is accepted.
void check_resume_flags(const TrainArguments& args, const RunSettings& run) {
  const auto given = [&](const char* flag) {
    return std::find(args.given.begin(), args.given.end(), flag) != args.given.end();
  };
  std::string differ;
  // Integers of one signedness each: compared and printed exactly.
  const auto check = [&](const char* flag, bool asked, auto value, auto run_value) {
    if (!asked || value == run_value) return;
    differ += (differ.empty() ? "" : ", ") + std::string(flag) + " " + std::to_string(value) +
              " (the run's: " + std::to_string(run_value) + ")";
  };
  check("--seed", args.seed_given, args.seed, run.ppo.seed);
  check("--num-envs", args.num_envs > 0, std::int64_t{args.num_envs}, run.ppo.num_envs);
  check("--threads", given("--threads"), args.threads, run.num_threads);
  check("--torch-threads", given("--torch-threads"), args.torch_threads, run.torch_threads);
  check("--checkpoint-every", given("--checkpoint-every"), args.checkpoint_every,
        run.checkpoint_every);
  check("--keep-checkpoints", given("--keep-checkpoints"), args.keep_checkpoints,
        run.keep_checkpoints);
  check("--eval-episodes", given("--eval-episodes"), args.eval_episodes, run.eval_episodes);
  if (!differ.empty()) {
    throw UsageError("train --resume continues with the settings in " + args.resume +
                     "/config.json, and these differ from them: " + differ +
                     " (only --steps and --minutes may change)");
  }
}

double mean_of(const std::deque<double>& values) {
  if (values.empty()) return std::nan("");
  double sum = 0.0;
  for (const double v : values) sum += v;
  return sum / static_cast<double>(values.size());
}

double std_of(const std::deque<double>& values) {
  if (values.empty()) return std::nan("");
  const double mean = mean_of(values);
  double squares = 0.0;
  for (const double v : values) squares += (v - mean) * (v - mean);
  return std::sqrt(squares / static_cast<double>(values.size()));
}

int run_train(const TrainArguments& args) {
  ppo::tune_process_for_training();
  RunSettings settings;
  std::optional<ppo::LoadedCheckpoint> checkpoint;
  json meta;                    // the checkpoint's progress (with --resume)
  double budget_minutes = 0.0;  // of wall time over the whole run; 0: none
  fs::path folder;
  if (!args.resume.empty()) {
    folder = args.resume;
    std::ifstream config_file(folder / "config.json");
    if (!config_file) {
      throw std::runtime_error("--resume " + folder.string() + ": no config.json there");
    }
    const json config = json::parse(config_file);
    settings = settings_from_json(config, folder / "config.json");
    check_resume_flags(args, settings);
    // The budget as the latest resume left it (a --steps or --minutes given then holds on).
    budget_minutes = settings.minutes;
    if (config.contains("resumes") && config.at("resumes").is_array() &&
        !config.at("resumes").empty()) {
      const json& latest = config.at("resumes").back();
      settings.ppo.total_env_steps = latest.value("total_env_steps", settings.ppo.total_env_steps);
      budget_minutes = latest.value("minutes", budget_minutes);
    }
    const ppo::CheckpointSearch search = ppo::find_latest_checkpoint(folder);
    for (const auto& skipped : search.skipped) {
      std::cerr << "train: skipping " << skipped.path.string() << ": " << skipped.reason << "\n";
    }
    if (!search.latest) {
      throw std::runtime_error("--resume " + folder.string() + ": no valid checkpoint there");
    }
    checkpoint = *search.latest;
    meta = read_meta(checkpoint->blobs, checkpoint->path);
  } else {
    settings.id = args.id;
    settings.sets = args.sets;
    settings.wraps = args.wraps;
    if (!args.config_file.empty()) {
      std::ifstream in(args.config_file);
      if (!in) throw UsageError("--config " + args.config_file + ": cannot read it");
      std::stringstream text;
      text << in.rdbuf();
      settings.ppo = ppo::config_from_json(text.str());
    }
    if (args.seed_given) settings.ppo.seed = args.seed;
    if (args.num_envs > 0) settings.ppo.num_envs = args.num_envs;
    settings.num_threads = args.threads;
    settings.torch_threads = args.torch_threads;
    settings.checkpoint_every = args.checkpoint_every;
    settings.keep_checkpoints = args.keep_checkpoints;
    settings.eval_episodes = args.eval_episodes;
    folder = args.out.empty() ? fs::path("runs") / settings.id : fs::path(args.out);
  }
  if (args.steps > 0) settings.ppo.total_env_steps = args.steps;
  // The wall time of the run before this process: its checkpoint's.
  const double wall_before = checkpoint ? meta.at("wall_time_s").get<double>() : 0.0;
  if (args.minutes > 0.0) {
    if (!checkpoint) settings.minutes = args.minutes;  // config.json's: the run's first budget
    budget_minutes = wall_before / 60.0 + args.minutes;
  }
  settings.ppo.validate();
  if (checkpoint) {
    const auto steps_done = meta.at("env_steps").get<std::int64_t>();
    if (args.steps > 0 && args.steps <= steps_done) {
      throw UsageError("train --resume --steps " + std::to_string(args.steps) + ": the run has " +
                       std::to_string(steps_done) + " env steps done; give more to train on");
    }
    const bool steps_spent = steps_done >= settings.ppo.total_env_steps;
    const bool time_spent = budget_minutes > 0.0 && wall_before >= budget_minutes * 60.0;
    // Nothing left to do once the run's summary is of its last checkpoint: say so, and leave the
    // run as it is. (A run killed between its last checkpoint and its evaluation goes on to
    // evaluate and write final.mp4 and summary.json.)
    bool summarized = false;
    if (std::ifstream summary_file(folder / "summary.json"); summary_file) {
      const json summary = json::parse(summary_file, nullptr, /*allow_exceptions=*/false);
      summarized = summary.is_object() && summary.contains("env_steps") &&
                   summary.at("env_steps") == steps_done;
    }
    if ((steps_spent || time_spent) && summarized) {
      std::ostringstream message;
      message << "--resume " << folder.string() << ": nothing to do, the run has spent its ";
      if (steps_spent) {
        message << "env steps (" << steps_done << " of " << settings.ppo.total_env_steps
                << "): give --steps N (more than " << steps_done << ") to train on\n";
      } else {
        message << "time (" << std::fixed << std::setprecision(1) << wall_before / 60.0 << " of "
                << budget_minutes << " minutes): give --minutes M to train M more\n";
      }
      std::cout << message.str();
      return 0;
    }
  }
  // The count in use goes into config.json, so that --resume runs with it (results depend on it).
  settings.torch_threads = set_torch_threads(settings.torch_threads);

  const std::unique_ptr<vector::VectorEnv> env = make_training_env(settings);
  ppo::Trainer trainer(*env, settings.ppo);
  std::deque<double> returns;
  std::optional<ppo::RunFolder> run;
  if (checkpoint) {
    load_blob(checkpoint->blobs, "model", trainer.policy_ptr(), checkpoint->path);
    load_blob(checkpoint->blobs, "optimizer", trainer.optimizer(), checkpoint->path);
    ppo::TrainerRngState rng;
    load_blob(checkpoint->blobs, "rng_sampling", rng.sampling, checkpoint->path);
    load_blob(checkpoint->blobs, "rng_augmentation", rng.augmentation, checkpoint->path);
    trainer.set_rng_state(rng);
    trainer.set_progress(meta.at("env_steps").get<std::int64_t>(),
                         meta.at("updates").get<std::int64_t>());
    for (const double r : meta.at("recent_returns").get<std::vector<double>>()) {
      returns.push_back(r);
    }
    const json& scaling_json = meta.at("reward_scaling");
    ppo::RewardScaling scaling;
    scaling.statistics.mean = {scaling_json.at("mean").get<double>()};
    scaling.statistics.var = {scaling_json.at("var").get<double>()};
    scaling.statistics.count = scaling_json.at("count").get<double>();
    scaling.returns = scaling_json.at("returns").get<std::vector<double>>();
    trainer.set_reward_scaling(std::move(scaling));
    // The budget from here on: the env steps, and the minutes of wall time over the whole run
    // (0: none), with the --minutes this resume was given when it was.
    json budget = {{"total_env_steps", settings.ppo.total_env_steps}, {"minutes", budget_minutes}};
    if (args.minutes > 0.0) budget["minutes_given"] = args.minutes;
    run.emplace(ppo::RunFolder::resume(folder, trainer.env_steps(), budget));
    std::cout << "resuming " << folder.string() << " from " << checkpoint->path.filename().string()
              << " (" << trainer.env_steps() << " env steps, " << trainer.updates() << " updates)\n"
              << "torch_threads=" << settings.torch_threads << " (as the run began)\n";
    const auto actions = checkpoint->blobs.find("env_actions");
    if (actions != checkpoint->blobs.end()) {
      // The envs continue their episodes where the checkpoint left them, so the resumed run
      // is the run that did not stop (same parameters, update for update).
      const auto replay_start = std::chrono::steady_clock::now();
      trainer.replay_env(actions->second);
      std::cout
          << "replayed the " << trainer.env_steps() << " env steps of the checkpoint in "
          << std::fixed << std::setprecision(1)
          << std::chrono::duration<double>(std::chrono::steady_clock::now() - replay_start).count()
          << std::defaultfloat << " s: the envs continue their episodes\n";
      // A checkpoint from before the digest was kept has none, and one taken before the envs
      // were first reset has 0: nothing to compare.
      const std::uint64_t digest = meta.value("env_digest", std::uint64_t{0});
      if (digest != 0 && digest != trainer.env_digest()) {
        std::cout << "warning: the replayed envs are not where the checkpoint's were (their "
                     "observations or episodes differ): the code or a library changed since "
                     "the run began, or the envs are not deterministic. Training goes on from "
                     "here, but it is no longer the run that did not stop.\n";
      }
    } else {
      std::cout << "the checkpoint has no env actions (written before they were kept): the envs "
                   "start new episodes\n";
    }
  } else {
    run.emplace(ppo::RunFolder::create(folder, settings_to_json(settings), kExtraColumns));
  }

  const std::string title = settings.id + " (" + folder.filename().string() + ")";
  ppo::ProgressLine progress(std::cout, ppo::ProgressLine::mode_for_stdout(args.quiet), 10,
                             ppo::ProgressLine::stdout_columns());
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&] {
    return wall_before +
           std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  // The run's time budget counts its whole wall time, as of its latest checkpoint: a killed
  // 10-minute run, resumed, trains for what was left of its 10 minutes. --minutes M given to
  // this command adds M to the wall time so far, and always allows one update.
  const double time_limit_s = budget_minutes * 60.0;
  bool one_update_due = args.minutes > 0.0;
  // Where the run stands, before any update of this process (what the line shows should none
  // be left to do).
  ppo::ProgressStatus status{trainer.env_steps(), settings.ppo.total_env_steps, elapsed(),
                             time_limit_s,        ppo::ProgressStatus::kNone,   mean_of(returns)};
  const auto save_checkpoint = [&] {
    ppo::write_checkpoint(run->checkpoint_path(trainer.updates()),
                          checkpoint_blobs(settings, trainer, returns, elapsed()));
    ppo::prune_checkpoints(run->path(), settings.keep_checkpoints);
  };
  while (trainer.env_steps() < settings.ppo.total_env_steps &&
         (time_limit_s <= 0.0 || one_update_due || elapsed() < time_limit_s)) {
    one_update_due = false;
    const auto update_start = std::chrono::steady_clock::now();
    const std::int64_t steps_before = trainer.env_steps();
    const ppo::RolloutStats rollout = trainer.collect();
    const auto learn_start = std::chrono::steady_clock::now();
    const ppo::UpdateStats update = trainer.update();
    const double update_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - learn_start).count();
    for (const ppo::Episode& episode : rollout.episodes) {
      returns.push_back(episode.episode_return);
      if (returns.size() > kReturnWindow) returns.pop_front();
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - update_start).count();
    ppo::ProgressRow row;
    row.steps = trainer.env_steps();
    row.wall_time_s = elapsed();
    row.fps = static_cast<double>(trainer.env_steps() - steps_before) / seconds;
    row.episode_return_mean = mean_of(returns);
    row.episode_return_std = std_of(returns);
    row.policy_loss = update.policy_loss;
    row.value_loss = update.value_loss;
    row.entropy = update.entropy;
    row.approx_kl = update.approx_kl;
    row.clip_fraction = update.clip_fraction;
    row.extra = {{"explained_variance", update.explained_variance},
                 {"grad_norm", update.grad_norm},
                 {"learning_rate", update.learning_rate},
                 {"env_s", rollout.env_seconds},
                 {"act_s", rollout.policy_seconds},
                 {"update_s", update_s}};
    run->append_progress(row);
    run->write_curve(title);
    if (trainer.updates() % settings.checkpoint_every == 0) save_checkpoint();
    status = {
        trainer.env_steps(),    settings.ppo.total_env_steps, elapsed(), time_limit_s, row.fps,
        row.episode_return_mean};
    progress.update(status);
  }
  progress.finish(status);
  save_checkpoint();
  env->close();

  const fs::path video = run->path() / "final.mp4";
  const Evaluation evaluation = evaluate(trainer.policy(), settings, settings.eval_episodes,
                                         settings.ppo.seed + 1'000'000, false, video);
  json summary;
  summary["env_id"] = settings.id;
  summary["env_steps"] = trainer.env_steps();
  summary["updates"] = trainer.updates();
  summary["wall_time_s"] = elapsed();
  summary["evaluation"] = evaluation_json(evaluation, settings.ppo.seed + 1'000'000, false);
  summary["video"] = video.filename().string();
  run->write_summary(summary);
  std::cout << "evaluation: return " << evaluation.mean << " +/- " << evaluation.std << " over "
            << evaluation.returns.size() << " episodes\n"
            << "wrote " << run->path().string() << "/{config.json, progress.csv, curve.png, "
            << run->checkpoint_path(trainer.updates()).filename().string()
            << ", final.mp4, summary.json}\n";
  return 0;
}

CLI::App* add_run_options(CLI::App& train, TrainArguments& args) {
  train.add_option("--config", args.config_file,
                   "PPO settings as JSON (any subset of the fields; the rest keep their defaults: "
                   "see examples/ppo/ppo.h, PpoConfig)");
  train.add_option("--steps", args.steps,
                   "Env steps to train for, all envs together; with --set action_repeat=K "
                   "each is K control steps (default: the config's total_env_steps, 1,000,000)");
  train
      .add_option("--minutes", args.minutes,
                  "Stop after this much wall time (then checkpoint, evaluate, write the video); "
                  "with --resume, this much more, and at least one update (without it, a "
                  "resumed run stops when its whole wall time reaches its budget so far)")
      ->check(CLI::Range(0.0, 1e9));
  return &train;
}

Command add_train(CLI::App& app) {
  auto args = std::make_shared<TrainArguments>();
  CLI::App* train = app.add_subcommand(
      "train",
      "Train a PPO policy from the env's observations (pixels included) and write a run folder: "
      "config.json, progress.csv, curve.png, checkpoints, and at the end final.mp4 and "
      "summary.json (an evaluation over seeded episodes)");
  train->add_option("id", args->id, "Env id, e.g. CartPoleBalance-v0 (`pixelgym list` shows them)");
  add_set_option(*train, args->sets);
  add_wrap_option(*train, args->wraps);
  add_run_options(*train, *args);
  train->add_option("--out", args->out, "The run folder (default runs/ID); must not hold a run");
  train->add_option("--resume", args->resume,
                    "Continue the run in this folder from its latest valid checkpoint (its "
                    "config.json gives the env and the settings; --steps and --minutes may "
                    "change the budget, and a run setting such as --threads given with it must "
                    "equal the run's). The envs replay the checkpoint's actions and go on "
                    "with their episodes, so with the run's --steps (the learning rate anneals "
                    "over it) the result is the run that did not stop");
  train->add_flag("--quiet", args->quiet,
                  "No progress bar: a plain line every 10 updates (also when stdout is not a "
                  "terminal)");
  train
      ->add_option(
          "--seed", args->seed,
          "Seed for torch, the envs and augmentation (default: the config's seed, 0 unless "
          "--config sets it)")
      ->each([args](const std::string&) { args->seed_given = true; });
  train
      ->add_option(
          "--num-envs", args->num_envs,
          "Envs stepped together (default: the config's num_envs, 8 unless --config sets it)")
      ->check(integer_in(1));
  train->add_option("--threads", args->threads, "Env threads (AsyncVectorEnv)")
      ->capture_default_str()
      ->check(integer_in(1));
  train
      ->add_option("--torch-threads", args->torch_threads,
                   "LibTorch intra-op threads for the forward passes and updates (0: one per "
                   "core this process may run on, or OMP_NUM_THREADS when set); config.json "
                   "records the count used and --resume keeps it")
      ->capture_default_str()
      ->check(integer_in(0));
  train
      ->add_option("--keep-checkpoints", args->keep_checkpoints,
                   "The newest checkpoints kept in the run folder, older ones deleted after each "
                   "new one is written (0: keep all; a checkpoint is about 5 MB at the demo's "
                   "settings, written every --checkpoint-every updates)")
      ->capture_default_str()
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{1} << 40));
  train->add_option("--checkpoint-every", args->checkpoint_every, "Updates between checkpoints")
      ->capture_default_str()
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 40));
  train
      ->add_option("--eval-episodes", args->eval_episodes,
                   "Seeded episodes of the final evaluation (deterministic actions)")
      ->capture_default_str()
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 20));
  return {train, [args, train] {
            if (args->resume.empty() && args->id.empty()) {
              throw UsageError("train: give an env id, or --resume RUN_FOLDER");
            }
            if (!args->resume.empty() &&
                (!args->id.empty() || !args->sets.empty() || !args->wraps.empty() ||
                 !args->config_file.empty() || !args->out.empty())) {
              throw UsageError(
                  "train --resume takes the env and settings from the run's config.json: give no "
                  "id, --set, --wrap, --config or --out with it");
            }
            for (const char* flag : {"--threads", "--torch-threads", "--checkpoint-every",
                                     "--keep-checkpoints", "--eval-episodes"}) {
              if (train->count(flag) > 0) args->given.emplace_back(flag);
            }
            return run_train(*args);
          }};
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
  ppo::tune_process_for_training();
  const fs::path given(args.run);
  fs::path checkpoint_path;
  fs::path folder;
  ppo::CheckpointBlobs blobs;
  if (fs::is_directory(given)) {
    folder = given;
    const ppo::CheckpointSearch search = ppo::find_latest_checkpoint(folder);
    for (const auto& skipped : search.skipped) {
      std::cerr << "eval: skipping " << skipped.path.string() << ": " << skipped.reason << "\n";
    }
    if (!search.latest) throw std::runtime_error("eval: no valid checkpoint in " + args.run);
    checkpoint_path = search.latest->path;
    blobs = search.latest->blobs;
  } else {
    checkpoint_path = given;
    folder = given.parent_path().empty() ? fs::path(".") : given.parent_path();
    blobs = ppo::read_checkpoint(checkpoint_path);
  }
  // The settings the checkpoint carries (a checkpoint file copied anywhere evaluates), else
  // (checkpoints from before they carried them) its run folder's config.json.
  RunSettings settings;
  if (const auto embedded = blobs.find("config"); embedded != blobs.end()) {
    settings = settings_from_json(json::parse(embedded->second), checkpoint_path);
  } else {
    std::ifstream config_file(folder / "config.json");
    if (!config_file) {
      throw std::runtime_error("eval: " + checkpoint_path.string() +
                               " does not carry its run's settings, and there is no config.json "
                               "in " +
                               folder.string() + " (the run folder it belongs to)");
    }
    settings = settings_from_json(json::parse(config_file), folder / "config.json");
  }
  // The run's thread count: a float sum over other threads can round differently, and the
  // evaluation would then differ from the run's summary.json.
  set_torch_threads(settings.torch_threads);
  // The spaces come from one env built as the run's.
  std::unique_ptr<Env> probe = wrappers::apply_wrappers(
      make(settings.id, parse_sets(settings.id, settings.sets)), settings.wraps);
  auto policy = std::make_shared<ppo::Policy>(probe->observation_space(), probe->action_space(),
                                              settings.ppo.policy);
  probe->close();
  load_blob(blobs, "model", policy, checkpoint_path);
  policy->eval();
  std::optional<fs::path> video;
  if (!args.video.empty()) video = fs::path(args.video);
  const Evaluation evaluation =
      evaluate(*policy, settings, args.episodes, args.seed, args.stochastic, video);
  std::cout << checkpoint_path.string() << ": " << settings.id << ", " << args.episodes
            << " episodes from seed " << args.seed
            << (args.stochastic ? ", sampled actions" : ", deterministic actions") << "\n";
  for (std::size_t e = 0; e < evaluation.returns.size(); ++e) {
    std::cout << "episode " << e << ": return=" << evaluation.returns[e] << "\n";
  }
  std::cout << "return_mean=" << evaluation.mean << " return_std=" << evaluation.std
            << " clipped_action_fraction=" << evaluation.clipped_fraction << "\n";
  if (video) std::cout << "wrote " << video->string() << "\n";
  return 0;
}

Command add_eval(CLI::App& app) {
  auto args = std::make_shared<EvalArguments>();
  CLI::App* eval = app.add_subcommand(
      "eval",
      "Evaluate a trained policy (a run folder's latest checkpoint, or a checkpoint "
      "file) over seeded episodes: each return, then their mean and std, and for Box actions "
      "clipped_action_fraction= (the share of action elements the policy put outside the "
      "bounds: near 1 is bang-bang control)");
  eval->add_option("run", args->run, "Run folder or checkpoint file (.pgck)")->required();
  eval->add_option("--episodes", args->episodes, "Episodes, seeded seed, seed + 1, ...")
      ->capture_default_str()
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 20));
  add_seed_option(*eval, args->seed, "Seed of the first episode");
  eval->add_option("--video", args->video, "Record the first episode to this .mp4");
  eval->add_flag("--stochastic", args->stochastic,
                 "Sample actions from the policy instead of taking its mean / most likely one");
  return {eval, [args] { return run_eval(*args); }};
}

}  // namespace

std::vector<Command> add_train_commands(CLI::App& app) { return {add_train(app), add_eval(app)}; }

}  // namespace pixelgym::cli
