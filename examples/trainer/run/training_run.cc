#include "pixelgym/trainer/training_run.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "pixelgym/trainer/atomic_file.h"
#include "pixelgym/trainer/curve_plot.h"
#include "pixelgym/trainer/evaluation.h"
#include "pixelgym/trainer/observation_summary.h"
#include "pixelgym/trainer/process_tuning.h"

namespace pixelgym::trainer {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Episodes whose returns the progress rows summarize at most (as Stable-Baselines3's
// ep_info_buffer), and the share of the env steps done that their window spans at least.
constexpr std::size_t kReturnWindow = 100;
constexpr std::int64_t kReturnWindowStepsDivisor = 10;

// Env steps of the evaluation cost's measurement (each of plain and recorded).
constexpr std::int64_t kCostProbeSteps = 20;
// Seconds kept for the last checkpoint and the end of the iteration in progress.
constexpr double kCheckpointMarginS = 1.0;

using Returns = RecentReturns;

double mean_of(const Returns& values) {
  if (values.empty()) return std::nan("");
  double sum = 0.0;
  for (const auto& v : values) sum += v.second;
  return sum / static_cast<double>(values.size());
}

double std_of(const Returns& values) {
  if (values.empty()) return std::nan("");
  const double mean = mean_of(values);
  double squares = 0.0;
  for (const auto& v : values) squares += (v.second - mean) * (v.second - mean);
  return std::sqrt(squares / static_cast<double>(values.size()));
}

// eval.csv's rows as curve.png draws them.
EvaluationPoints evaluation_points(const std::vector<EvalRow>& rows) {
  EvaluationPoints points;
  for (const EvalRow& row : rows) {
    points.steps.push_back(static_cast<double>(row.steps));
    points.wall_time_s.push_back(row.wall_time_s);
    points.mean.push_back(row.return_mean);
    points.std.push_back(row.return_std);
  }
  return points;
}

std::string one_decimal(double s) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(1) << s;
  return text.str();
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

json read_meta(const LoadedCheckpoint& checkpoint) {
  const auto found = checkpoint.blobs.find("meta");
  if (found == checkpoint.blobs.end()) {
    throw std::runtime_error(checkpoint.path.string() + ": the checkpoint has no \"meta\" entry");
  }
  return json::parse(found->second);
}

// RunRequestError naming each setting of `given` that differs from the run's.
void check_resume_settings(const ResumeChecks& given, const RunSettings& run,
                           const fs::path& folder) {
  std::string differ;
  // Integers of one signedness each: compared and printed exactly.
  const auto check = [&](const char* flag, const auto& value, auto run_value) {
    if (!value || *value == run_value) return;
    differ += (differ.empty() ? "" : ", ") + std::string(flag) + " " + std::to_string(*value) +
              " (the run's: " + std::to_string(run_value) + ")";
  };
  check("--seed", given.seed, run.seed());
  check("--num-envs", given.num_envs, run.num_envs());
  check("--threads", given.num_threads, run.num_threads);
  check("--torch-threads", given.torch_threads, run.torch_threads);
  check("--checkpoint-every", given.checkpoint_every, run.checkpoint_every);
  check("--keep-checkpoints", given.keep_checkpoints, run.keep_checkpoints);
  check("--eval-episodes", given.eval_episodes, run.eval_episodes);
  check("--eval-every", given.eval_every, run.eval_every);
  check("--eval-every-episodes", given.eval_every_episodes, run.eval_every_episodes);
  if (!differ.empty()) {
    throw RunRequestError("train --resume continues with the settings in " + folder.string() +
                          "/config.json, and these differ from them: " + differ +
                          " (only --steps and --minutes may change)");
  }
}

// "rank{r}." : the prefix of rank r's blobs in a distributed checkpoint.
std::string rank_prefix(int rank) { return "rank" + std::to_string(rank) + "."; }

std::string hex_digest(std::uint64_t digest) {
  std::ostringstream text;
  text << std::hex << std::setw(16) << std::setfill('0') << digest;
  return text.str();
}

// Rank r's view of a distributed checkpoint: rank 0's blobs with rank r's "rank{r}.*" in place
// of theirs, no other rank's, and rank r's meta members over rank 0's.
CheckpointBlobs rank_checkpoint(const CheckpointBlobs& all, int rank, int world,
                                const fs::path& path) {
  CheckpointBlobs mine;
  for (const auto& [name, bytes] : all) {
    if (name.rfind("rank", 0) == 0 && name.find('.') != std::string::npos &&
        name.find_first_not_of("0123456789", 4) == name.find('.')) {
      continue;  // some rank's own
    }
    mine[name] = bytes;
  }
  if (rank == 0) return mine;
  const std::string prefix = rank_prefix(rank);
  const auto meta = all.find(prefix + "meta");
  if (meta == all.end()) {
    throw std::runtime_error(path.string() + ": the checkpoint has no \"" + prefix +
                             "meta\" entry: it is not of a run of " + std::to_string(world) +
                             " ranks");
  }
  for (const auto& [name, bytes] : all) {
    if (name.rfind(prefix, 0) == 0 && name != prefix + "meta") {
      mine[name.substr(prefix.size())] = bytes;
    }
  }
  // Rank 0's env actions are not rank r's: without its own there are none.
  if (all.count(prefix + "env_actions") == 0) mine.erase("env_actions");
  json merged = json::parse(mine.at("meta"));
  const json own = json::parse(meta->second);
  for (auto member = own.begin(); member != own.end(); ++member) merged[member.key()] = *member;
  mine["meta"] = merged.dump();
  return mine;
}

const char* const kEvalHeader = "steps,wall_time_s,return_mean,return_std,episodes,eval_s";

}  // namespace

void add_recent_returns(RecentReturns& recent, const std::vector<double>& returns,
                        std::int64_t steps, std::int64_t iteration_steps) {
  for (const double episode_return : returns) {
    recent.emplace_back(steps, episode_return);
    if (recent.size() > kReturnWindow) recent.pop_front();
  }
  const std::int64_t window =
      std::max(steps / kReturnWindowStepsDivisor, std::max<std::int64_t>(iteration_steps, 1));
  while (recent.size() > 1 && recent.front().first < steps - window) recent.pop_front();
}

std::string format_eval_csv(const std::vector<EvalRow>& rows) {
  std::ostringstream out;
  out << kEvalHeader << "\n" << std::setprecision(17);
  for (const EvalRow& row : rows) {
    out << row.steps << "," << row.wall_time_s << "," << row.return_mean << "," << row.return_std
        << "," << row.episodes << "," << row.eval_s << "\n";
  }
  return out.str();
}

std::vector<EvalRow> parse_eval_csv(const std::string& text, const std::string& source) {
  std::istringstream in(text);
  std::string line;
  std::vector<EvalRow> rows;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto fail = [&](const std::string& what) {
      throw std::runtime_error(source + ": line " + std::to_string(number) + ": " + what);
    };
    if (number == 1) {
      if (line != kEvalHeader) fail(std::string("expected the header \"") + kEvalHeader + "\"");
      continue;
    }
    std::istringstream fields(line);
    EvalRow row;
    char c1 = 0, c2 = 0, c3 = 0, c4 = 0, c5 = 0;
    fields >> row.steps >> c1 >> row.wall_time_s >> c2 >> row.return_mean >> c3 >> row.return_std >>
        c4 >> row.episodes >> c5 >> row.eval_s;
    if (!fields || c1 != ',' || c2 != ',' || c3 != ',' || c4 != ',' || c5 != ',' ||
        !(fields >> std::ws).eof()) {
      fail("expected six numbers separated by commas, got \"" + line + "\"");
    }
    rows.push_back(row);
  }
  if (number == 0) throw std::runtime_error(source + ": empty (no header)");
  return rows;
}

TrainingRun::TrainingRun(const AlgorithmFactory& algorithm, RunSettings settings, fs::path folder,
                         RunOutput output)
    : factory_(&algorithm),
      settings_(std::move(settings)),
      folder_(std::move(folder)),
      output_(output) {}

TrainingRun TrainingRun::create(const AlgorithmFactory& algorithm, RunSettings settings,
                                fs::path folder, TrainBudget budget, RunOutput output) {
  settings.algorithm = algorithm.name();
  TrainingRun run(algorithm, std::move(settings), std::move(folder), output);
  if (budget.minutes > 0.0) run.settings_.minutes = budget.minutes;  // the run's first budget
  run.apply_budget(budget);
  return run;
}

TrainingRun TrainingRun::resume(const AlgorithmFactory& algorithm, fs::path folder,
                                TrainBudget budget, const ResumeChecks& given, RunOutput output) {
  const json config = read_run_config(folder / "config.json", "--resume " + folder.string());
  RunSettings settings = settings_from_json(config, folder / "config.json", algorithm);
  check_resume_settings(given, settings, folder);
  // Before the checkpoint is read: a run being trained by another process is left to it.
  RunLock lock = RunLock::acquire(folder, "train --resume");
  TrainingRun run(algorithm, std::move(settings), std::move(folder), output);
  run.lock_ = std::move(lock);
  run.load_resume_point(config);
  run.apply_budget(budget);
  return run;
}

void TrainingRun::load_resume_point(const json& config) {
  // The budget as the latest resume left it (a --steps or --minutes given then holds on).
  budget_minutes_ = settings_.minutes;
  if (config.contains("resumes") && config.at("resumes").is_array() &&
      !config.at("resumes").empty()) {
    const json& latest = config.at("resumes").back();
    settings_.algorithm_config["total_env_steps"] =
        latest.value("total_env_steps", settings_.total_env_steps());
    budget_minutes_ = latest.value("minutes", budget_minutes_);
  }
  CheckpointSearch search = find_latest_checkpoint(folder_);
  for (const auto& skipped : search.skipped) {
    output_.errors << "train: skipping " << skipped.path.string() << ": " << skipped.reason << "\n";
  }
  if (!search.latest && search.skipped.empty()) {
    // Stopped before its first checkpoint: nothing was saved to go on from, so the run starts
    // again from its first step, with the settings of its config.json.
    restart_ = true;
    output_.out << "train: " << folder_.string()
                << " stopped before its first checkpoint: starting it afresh\n";
    return;
  }
  if (!search.latest) {
    throw std::runtime_error(
        "--resume " + folder_.string() + ": no valid checkpoint there (the " +
        std::to_string(search.skipped.size()) +
        " above cannot be read); remove them to start the run afresh with --resume, or train "
        "into another --out");
  }
  checkpoint_ = std::move(search.latest);
  meta_ = read_meta(*checkpoint_);
  // The checkpoint's own settings are the run's: a config.json edited since (another env, a
  // wider network, another batch) would be recorded as the run's while the checkpoint's network
  // and envs go on, or would train another env from this one's state.
  if (const auto saved = checkpoint_->blobs.find("config"); saved != checkpoint_->blobs.end()) {
    const json saved_json = json::parse(saved->second, nullptr, /*allow_exceptions=*/false);
    const std::string differ = settings_differences(
        settings_, settings_from_json(saved_json, checkpoint_->path, *factory_));
    if (!differ.empty()) {
      throw std::runtime_error(
          "--resume " + folder_.string() + ": config.json differs from the settings " +
          checkpoint_->path.filename().string() + " was trained with (" + differ +
          "); config.json was edited after the run started: restore it, or train a new run "
          "with these settings into another --out");
    }
  }
  wall_before_s_ = meta_.at("wall_time_s").get<double>();
}

void TrainingRun::apply_budget(const TrainBudget& budget) {
  if (budget.steps > 0) settings_.algorithm_config["total_env_steps"] = budget.steps;
  minutes_given_ = budget.minutes;
  if (budget.minutes > 0.0) budget_minutes_ = wall_before_s_ / 60.0 + budget.minutes;
  settings_.algorithm_config = factory_->parse_config(settings_.algorithm_config.dump());
  if (!checkpoint_) return;
  const auto steps_done = meta_.at("env_steps").get<std::int64_t>();
  if (budget.steps > 0 && budget.steps <= steps_done) {
    throw RunRequestError("train --resume --steps " + std::to_string(budget.steps) +
                          ": the run has " + std::to_string(steps_done) +
                          " env steps done; give more to train on");
  }
}

bool TrainingRun::nothing_to_do() const {
  const auto steps_done = meta_.at("env_steps").get<std::int64_t>();
  const bool steps_spent = steps_done >= settings_.total_env_steps();
  const bool time_spent = budget_minutes_ > 0.0 && wall_before_s_ >= budget_minutes_ * 60.0;
  // Nothing is left to do once the run's summary is of its last checkpoint. (A run killed
  // between its last checkpoint and its evaluation goes on to evaluate and write final.mp4 and
  // summary.json.)
  bool summarized = false;
  if (std::ifstream summary_file(folder_ / "summary.json"); summary_file) {
    const json summary = json::parse(summary_file, nullptr, /*allow_exceptions=*/false);
    summarized = summary.is_object() && summary.contains("env_steps") &&
                 summary.at("env_steps") == steps_done;
  }
  if (!(steps_spent || time_spent) || !summarized) return false;
  std::ostringstream message;
  message << "--resume " << folder_.string() << ": nothing to do, the run has spent its ";
  if (steps_spent) {
    message << "env steps (" << steps_done << " of " << settings_.total_env_steps()
            << "): give --steps N (more than " << steps_done << ") to train on\n";
  } else {
    message << "time (" << std::fixed << std::setprecision(1) << wall_before_s_ / 60.0 << " of "
            << budget_minutes_ << " minutes): give --minutes M to train M more\n";
  }
  output_.out << message.str();
  return true;
}

TrainingRun TrainingRun::join(const AlgorithmFactories& algorithms, Communicator& communicator,
                              RunOutput output) {
  if (communicator.rank() == 0 || algorithms.empty()) {
    throw std::invalid_argument("TrainingRun::join: rank 0 creates or resumes the run");
  }
  TrainingRun run(*algorithms.front(), RunSettings{}, fs::path(), output);
  run.communicator_ = &communicator;
  run.join_algorithms_ = algorithms;
  return run;
}

void TrainingRun::distribute(Communicator& communicator) {
  if (communicator.rank() != 0) {
    throw std::invalid_argument("TrainingRun::distribute: rank " +
                                std::to_string(communicator.rank()) + " joins the run (join)");
  }
  communicator_ = &communicator;
}

bool TrainingRun::lead() const { return communicator_->rank() == 0; }

bool TrainingRun::distributed() const { return communicator_->world_size() > 1; }

void TrainingRun::send_start(bool nothing) {
  const int world = communicator_->world_size();
  std::vector<std::string> starts(static_cast<std::size_t>(world));
  for (int r = 1; r < world; ++r) {
    CheckpointBlobs start;
    start["settings"] = settings_to_json(settings_).dump();
    start["nothing_to_do"] = nothing ? "1" : "0";
    if (checkpoint_ && !nothing) {
      start["checkpoint_path"] = checkpoint_->path.string();
      start["checkpoint_update"] = std::to_string(checkpoint_->update);
      for (auto& [name, bytes] : rank_checkpoint(checkpoint_->blobs, r, world, checkpoint_->path)) {
        start["checkpoint." + name] = std::move(bytes);
      }
    }
    starts[static_cast<std::size_t>(r)] = pack_blobs(start);
  }
  communicator_->scatter_bytes(starts, "the run's start");
  if (checkpoint_ && !nothing) {
    checkpoint_->blobs = rank_checkpoint(checkpoint_->blobs, 0, world, checkpoint_->path);
  }
}

bool TrainingRun::receive_start() {
  const CheckpointBlobs start =
      unpack_blobs(communicator_->scatter_bytes({}, "the run's start"), "rank 0's start");
  if (start.at("nothing_to_do") == "1") return false;
  const json settings = json::parse(start.at("settings"));
  factory_ = &algorithm_of(settings, "rank 0's config", join_algorithms_);
  settings_ = settings_from_json(settings, "rank 0's config", *factory_);
  if (start.count("checkpoint_path") != 0) {
    LoadedCheckpoint checkpoint;
    checkpoint.path = start.at("checkpoint_path");
    checkpoint.update = std::stoll(start.at("checkpoint_update"));
    const std::string prefix = "checkpoint.";
    for (const auto& [name, bytes] : start) {
      if (name.rfind(prefix, 0) == 0) checkpoint.blobs[name.substr(prefix.size())] = bytes;
    }
    checkpoint_ = std::move(checkpoint);
    meta_ = read_meta(*checkpoint_);
    wall_before_s_ = meta_.at("wall_time_s").get<double>();
  }
  return true;
}

bool TrainingRun::keep_training(bool lead_says) {
  if (!distributed()) return lead_says;
  double go = lead() && lead_says ? 1.0 : 0.0;
  communicator_->all_reduce_sum(&go, 1, "rank 0's decision to train on");
  return go > 0.5;
}

std::vector<double> TrainingRun::gather_returns(const std::vector<double>& mine) {
  if (!distributed()) return mine;
  std::string bytes(mine.size() * sizeof(double), '\0');
  if (!mine.empty()) std::memcpy(bytes.data(), mine.data(), bytes.size());
  std::vector<double> all;
  for (const std::string& part : communicator_->gather_bytes(bytes, "episode returns")) {
    const std::size_t count = part.size() / sizeof(double);
    const std::size_t at = all.size();
    all.resize(at + count);
    if (count > 0) std::memcpy(all.data() + at, part.data(), count * sizeof(double));
  }
  return all;
}

std::optional<json> TrainingRun::train() {
  // The run folder is locked until train() returns or throws.
  struct ReleaseLock {
    std::optional<RunLock>& lock;
    ~ReleaseLock() { lock.reset(); }
  } release_lock{lock_};
  const int world = communicator_->world_size();
  if (lead()) {
    if (checkpoint_ && settings_.world_size != world) {
      throw RunRequestError(
          "train --resume " + folder_.string() + ": the run was trained by " +
          std::to_string(settings_.world_size) +
          (settings_.world_size == 1 ? " process" : " ranks") + " and this is " +
          (world == 1 ? "one process" : "a run of " + std::to_string(world) + " ranks") +
          "; resume it with " +
          (settings_.world_size == 1
               ? std::string("no --nproc (and no WORLD_SIZE)")
               : "--nproc " + std::to_string(settings_.world_size) +
                     " (or WORLD_SIZE=" + std::to_string(settings_.world_size) + ")") +
          ": each rank continues its own envs, so the world size cannot change");
    }
    settings_.world_size = world;
    const bool nothing = checkpoint_ && nothing_to_do();
    // The count in use goes into config.json, so that a resume runs with it (results depend on
    // it).
    const bool threads_given = settings_.torch_threads != 0;
    settings_.torch_threads = factory_->set_threads(settings_.torch_threads);
    // Said once the envs are made: an env the run refuses is its first and only word.
    if (!nothing) {
      busy_cores_warning_ =
          busy_cores_warning(settings_.torch_threads, threads_given, cpu_availability());
    }
    if (distributed()) send_start(nothing);
    if (nothing) {
      communicator_->finish();
      return std::nullopt;
    }
  } else {
    if (!receive_start()) {
      communicator_->finish();
      return std::nullopt;
    }
    settings_.torch_threads = factory_->set_threads(settings_.torch_threads);
  }
  const bool folder_existed = fs::exists(folder_);
  if (lead() && !lock_) lock_ = RunLock::acquire(folder_, "train");
  try {
    try {
      env_ = make_training_env(settings_);
    } catch (const std::invalid_argument& error) {
      // A new run's env config that `make` refuses (msaa more than this OpenGL offers) is the
      // request's fault; a resumed run's was made before.
      if (checkpoint_ || restart_) throw;
      throw RunRequestError(error.what());
    }
    const auto rank = static_cast<std::uint64_t>(communicator_->rank());
    loop_ = std::make_unique<EnvLoop>(
        *env_, settings_.seed() + rank * static_cast<std::uint64_t>(settings_.num_envs()),
        "run_episode");
    algorithm_ = factory_->make(*loop_, settings_.algorithm_config, *communicator_);
  } catch (...) {
    // Refused before anything was written (an env it cannot train on, settings that do not fit
    // in memory): a new run leaves no folder behind, only the lock it took.
    if (lead() && !checkpoint_ && !restart_) {
      std::error_code ignored;
      fs::remove(folder_ / ".lock", ignored);
      if (!folder_existed) fs::remove(folder_, ignored);  // only when empty
    }
    throw;
  }
  if (lead()) {
    if (!busy_cores_warning_.empty()) output_.out << busy_cores_warning_ << std::endl;
    output_.out << "observation: " << observation_summary(env_->single_observation_space())
                << std::endl;
  }
  if (checkpoint_) {
    restore_from_checkpoint();
  } else if (lead() && restart_) {
    // Rows logged before the stop are dropped (resumed at step 0), and so are evaluations.
    fs::remove(folder_ / "eval.csv");
    json budget = {{"total_env_steps", settings_.total_env_steps()}, {"minutes", budget_minutes_}};
    if (minutes_given_ > 0.0) budget["minutes_given"] = minutes_given_;
    run_.emplace(RunFolder::resume(folder_, 0, budget));
  } else if (lead()) {
    run_.emplace(
        RunFolder::create(folder_, settings_to_json(settings_), algorithm_->metric_names()));
  }
  train_until_spent();
  save_checkpoint();
  env_->close();
  if (!lead()) {
    communicator_->finish();
    return std::nullopt;
  }
  if (interrupted_) {
    output_.out << "interrupted at " << algorithm_->env_steps() << " env steps: wrote "
                << last_checkpoint_.string() << " (no final evaluation)" << std::endl;
    communicator_->finish();
    return std::nullopt;
  }
  json summary = evaluate_and_summarize();
  communicator_->finish();
  return summary;
}

void TrainingRun::restore_from_checkpoint() {
  algorithm_->set_progress(meta_.at("env_steps").get<std::int64_t>(),
                           meta_.at("updates").get<std::int64_t>());
  algorithm_->restore(*checkpoint_, meta_);
  const auto recent = meta_.at("recent_returns").get<std::vector<double>>();
  // Checkpoints written before the steps were kept: as if they ended at the checkpoint.
  const auto ended = meta_.value("recent_return_steps",
                                 std::vector<std::int64_t>(recent.size(), algorithm_->env_steps()));
  for (std::size_t i = 0; i < recent.size(); ++i) {
    returns_.emplace_back(i < ended.size() ? ended[i] : algorithm_->env_steps(), recent[i]);
  }
  // The budget from here on: the env steps, and the minutes of wall time over the whole run
  // (0: none), with the minutes this resume was given, when it was.
  json budget = {{"total_env_steps", settings_.total_env_steps()}, {"minutes", budget_minutes_}};
  if (minutes_given_ > 0.0) budget["minutes_given"] = minutes_given_;
  if (lead()) run_.emplace(RunFolder::resume(folder_, algorithm_->env_steps(), budget));
  if (lead() && fs::exists(folder_ / "eval.csv")) {
    for (const EvalRow& row :
         parse_eval_csv(read_whole_file(folder_ / "eval.csv", "train --resume"),
                        (folder_ / "eval.csv").string())) {
      if (row.steps <= algorithm_->env_steps()) evals_.push_back(row);
    }
  }
  output_.out << "resuming " << folder_.string() << " from "
              << checkpoint_->path.filename().string() << " (" << algorithm_->env_steps()
              << " env steps, " << algorithm_->updates() << " updates)\n"
              << "torch_threads=" << settings_.torch_threads << " (as the run began)\n";
  replay_env_actions();
}

void TrainingRun::replay_env_actions() {
  const auto actions = checkpoint_->blobs.find("env_actions");
  if (actions == checkpoint_->blobs.end()) {
    env_log_complete_ = algorithm_->env_steps() == 0;
    output_.out << "the checkpoint has no env actions (written before they were kept): the envs "
                   "start new episodes\n";
    return;
  }
  // The envs continue their episodes where the checkpoint left them, so the resumed run is the
  // run that did not stop (same parameters, update for update).
  const auto replay_start = std::chrono::steady_clock::now();
  // Distributed, a rank's own steps are not env_steps (every rank's), nor its share when
  // stragglers were preempted: its log holds whole batches of its own.
  const std::string& log = actions->second;
  const std::int64_t steps =
      distributed()
          ? static_cast<std::int64_t>(log.size() / loop_->batch_bytes()) * loop_->num_envs()
          : algorithm_->env_steps();
  loop_->replay(
      log, steps, [this](const Value& first) { algorithm_->replayed_reset(first); },
      [this](const Value& taken, const vector::VectorStepResult& step) {
        algorithm_->replayed_step(taken, step);
      });
  output_.out << "replayed the " << algorithm_->env_steps() << " env steps of the checkpoint in "
              << std::fixed << std::setprecision(1) << seconds_since(replay_start)
              << std::defaultfloat << std::setprecision(6)
              << " s: the envs continue their episodes\n";
  // Absent or 0 (a checkpoint taken before the envs were first reset): nothing to compare.
  const std::uint64_t digest = meta_.value("env_digest", std::uint64_t{0});
  if (digest != 0 && digest != loop_->digest()) {
    output_.out << "warning: the replayed envs are not where the checkpoint's were (their "
                   "observations or episodes differ): the code or a library changed since "
                   "the run began, or the envs are not deterministic. Training goes on from "
                   "here, but it is no longer the run that did not stop.\n";
  }
}

double TrainingRun::elapsed_s() const { return wall_before_s_ + seconds_since(start_); }

bool TrainingRun::interrupt_requested() const {
  return interrupt_ != nullptr && interrupt_->load();
}

void TrainingRun::update_training_deadline() {
  planned_ =
      plan_final_evaluation(kEvaluationShare * left_at_start_s_, *cost_, settings_.eval_episodes);
  // Never more than the share: an episode estimated at its longest (max_episode_steps) may end
  // far sooner, and training keeps the rest of the budget.
  const double kept =
      std::min(planned_.seconds, kEvaluationShare * std::max(left_at_start_s_, 0.0));
  training_deadline_s_ = time_limit_s_ - kept - kCheckpointMarginS;
}

void TrainingRun::plan_time_budget() {
  training_deadline_s_ = time_limit_s_;
  left_at_start_s_ = time_limit_s_ - elapsed_s();
  if (time_limit_s_ <= 0.0 || !lead()) return;
  const auto probe_start = std::chrono::steady_clock::now();
  cost_ =
      measure_evaluation_cost(algorithm_->actor(), settings_, run_->path(), kCostProbeSteps, [&] {
        progress_->tick_note("time budget: timing evaluation steps (" +
                             one_decimal(seconds_since(probe_start)) + " s so far)");
      });
  update_training_deadline();
  output_.out << "time budget: " << one_decimal(std::max(left_at_start_s_, 0.0))
              << " s left; an evaluation episode takes about "
              << one_decimal(cost_->episode_seconds(false)) << " s (its " << cost_->episode_steps
              << " steps at most"
              << (cost_->episode_steps_known ? "" : ", the env has no TimeLimit: 1000 assumed")
              << "), so training stops at about "
              << one_decimal(std::max(training_deadline_s_, 0.0)) << " s of the run's "
              << one_decimal(time_limit_s_) << " s to keep "
              << one_decimal(time_limit_s_ - kCheckpointMarginS - training_deadline_s_)
              << " s for the final evaluation (" << planned_.episodes
              << (planned_.episodes == 1 ? " episode" : " episodes")
              << (planned_.video ? ", the first recorded to final.mp4" : ", no video") << ")"
              << (planned_.note.empty() ? "" : ": " + planned_.note) << std::endl;
  progress_->wrote_line();
}

bool TrainingRun::stop_requested(std::int64_t env_steps) {
  if (!lead()) return false;
  status_.steps = env_steps;
  status_.elapsed_s = elapsed_s();
  progress_->tick(status_);
  // The ranks of a distributed run end their iterations together: between iterations only.
  if (distributed()) return false;
  return interrupt_requested() ||
         (time_limit_s_ > 0.0 && status_.elapsed_s >= training_deadline_s_);
}

void TrainingRun::train_until_spent() {
  const std::string title = settings_.env_id + " (" + folder_.filename().string() + ")";
  progress_.emplace(output_.out, output_.progress_mode, 10, output_.columns);
  start_ = std::chrono::steady_clock::now();
  // The time budget counts the run's whole wall time, as of its latest checkpoint: a killed
  // 10-minute run, resumed, trains for what was left of its 10 minutes. Minutes given to this
  // process add to the wall time so far, and always allow one update (which the budget may cut
  // short).
  time_limit_s_ = budget_minutes_ * 60.0;
  bool one_update_due = minutes_given_ > 0.0;
  const std::int64_t total_steps = settings_.total_env_steps();
  // Where the run stands before any update of this process (what the line shows should none be
  // left to do).
  status_ = {algorithm_->env_steps(), total_steps,           elapsed_s(),
             time_limit_s_,           ProgressStatus::kNone, mean_of(returns_)};
  plan_time_budget();
  const StopCheck stop = [this](std::int64_t steps) { return stop_requested(steps); };
  while (keep_training(
      algorithm_->env_steps() < total_steps && !interrupt_requested() &&
      (time_limit_s_ <= 0.0 || one_update_due || elapsed_s() < training_deadline_s_))) {
    one_update_due = false;
    const std::int64_t steps_before = algorithm_->env_steps();
    const ProgressRow row = iterate_once(stop);
    if (distributed() && algorithm_->updates() % kDigestEvery == 0) {
      parameter_digests_ = check_same_on_every_rank(*communicator_, algorithm_->parameter_digest(),
                                                    algorithm_->updates());
    }
    if (lead()) {
      evaluate_when_due(steps_before);
      run_->write_curve(title, evaluation_points(evals_));
    }
    if (algorithm_->updates() % settings_.checkpoint_every == 0) save_checkpoint();
    status_ = {algorithm_->env_steps(), total_steps, elapsed_s(),
               time_limit_s_,           row.fps,     row.episode_return_mean};
    progress_->update(status_);
  }
  progress_->finish(status_);
  interrupted_ = interrupt_requested();
  stopped_by_ = interrupted_                             ? "interrupt"
                : algorithm_->env_steps() >= total_steps ? "steps"
                                                         : "time";
}

ProgressRow TrainingRun::iterate_once(const StopCheck& stop) {
  const auto iteration_start = std::chrono::steady_clock::now();
  const std::int64_t steps_before = algorithm_->env_steps();
  IterationStats stats = algorithm_->iterate(stop);
  stats.episode_returns = gather_returns(stats.episode_returns);
  add_recent_returns(returns_, stats.episode_returns, algorithm_->env_steps(),
                     algorithm_->env_steps() - steps_before);
  const double seconds = seconds_since(iteration_start);
  ProgressRow row;
  row.steps = algorithm_->env_steps();
  row.wall_time_s = elapsed_s();
  row.fps = static_cast<double>(algorithm_->env_steps() - steps_before) / seconds;
  row.episode_return_mean = mean_of(returns_);
  row.episode_return_std = std_of(returns_);
  row.metrics = std::move(stats.metrics);
  if (lead()) run_->append_progress(row);
  return row;
}

void TrainingRun::report_skip(const std::string& reason, const std::string& line) {
  ++evaluations_skipped_;
  if (!skip_reasons_.insert(reason).second) return;
  output_.out << line << " (later evaluations skipped for this reason are not reported)"
              << std::endl;
  progress_->wrote_line();
}

void TrainingRun::evaluate_when_due(std::int64_t steps_before) {
  const std::int64_t every = settings_.eval_every;
  const std::int64_t steps = algorithm_->env_steps();
  if (every <= 0 || steps / every == steps_before / every) return;
  const double this_process_s = seconds_since(start_);
  const auto seconds = [](double s) {
    std::ostringstream text;
    text << std::fixed << std::setprecision(1) << s;
    return text.str();
  };
  if (eval_seconds_ > settings_.eval_max_share * this_process_s) {
    std::ostringstream share;
    share << settings_.eval_max_share;
    report_skip("share", "eval at " + std::to_string(steps) +
                             " env steps skipped: evaluations took " + seconds(eval_seconds_) +
                             " s of " + seconds(this_process_s) +
                             " s, more than --eval-max-share " + share.str());
    return;
  }
  if (cost_ && time_limit_s_ > 0.0) {
    const double needed = cost_->evaluation_seconds(settings_.eval_every_episodes, false);
    const double left = training_deadline_s_ - elapsed_s();
    if (needed > left) {
      report_skip("time", "eval at " + std::to_string(steps) +
                              " env steps skipped: it takes about " + seconds(needed) +
                              " s and the time budget leaves training " +
                              seconds(std::max(left, 0.0)) + " s");
      return;
    }
  }
  const auto eval_start = std::chrono::steady_clock::now();
  EvaluationRequest request;
  request.episodes = settings_.eval_every_episodes;
  request.seed = settings_.seed() + kEvaluationSeedOffset;
  request.on_step = [this, steps, eval_start] {
    progress_->tick_note("eval at " + std::to_string(steps) + " env steps: evaluating (" +
                         one_decimal(seconds_since(eval_start)) + " s so far)");
  };
  const PolicyEvaluation evaluation = evaluate(algorithm_->actor(), settings_, request);
  EvalRow row;
  row.steps = steps;
  row.wall_time_s = elapsed_s();
  row.return_mean = evaluation.mean;
  row.return_std = evaluation.std;
  row.episodes = settings_.eval_every_episodes;
  row.eval_s = seconds_since(eval_start);
  eval_seconds_ += row.eval_s;
  evals_.push_back(row);
  const std::string text = format_eval_csv(evals_);
  write_file_atomically(run_->path() / "eval.csv", {text}, "train");
  output_.out << "eval at " << steps << " env steps: return " << evaluation.mean << " +/- "
              << evaluation.std << " over " << row.episodes << " episodes (" << seconds(row.eval_s)
              << " s)" << std::endl;
  progress_->wrote_line();
  if (cost_ && evaluation.steps > 0) {
    // What the episodes cost now, for the final evaluation's share of the budget.
    double played_s = 0.0;
    for (const double s : evaluation.episode_s) played_s += s;
    cost_->step_s = played_s / static_cast<double>(evaluation.steps);
    update_training_deadline();
  }
}

void TrainingRun::save_checkpoint() {
  CheckpointBlobs blobs;
  json meta;
  algorithm_->save(blobs, meta);
  if (distributed()) {
    parameter_digests_ = check_same_on_every_rank(*communicator_, algorithm_->parameter_digest(),
                                                  algorithm_->updates());
    // Each rank's own part (generators, env actions, meta with its env digest) goes to rank 0.
    CheckpointBlobs mine;
    for (const std::string& name : algorithm_->rank_blobs()) mine[name] = blobs.at(name);
    if (env_log_complete_) mine["env_actions"] = loop_->action_log();
    json rank_meta = meta;
    rank_meta["env_digest"] = loop_->digest();
    mine["meta"] = rank_meta.dump();
    const std::vector<std::string> parts = communicator_->gather_bytes(
        pack_blobs(mine), "the checkpoint of update " + std::to_string(algorithm_->updates()));
    if (!lead()) return;
    for (std::size_t r = 1; r < parts.size(); ++r) {
      for (auto& [name, bytes] : unpack_blobs(parts[r], "rank " + std::to_string(r) + "'s part")) {
        blobs[rank_prefix(static_cast<int>(r)) + name] = std::move(bytes);
      }
    }
  }
  // The run's settings, so that a checkpoint file evaluates on its own (away from its folder).
  blobs["config"] = settings_to_json(settings_).dump();
  meta["env_steps"] = algorithm_->env_steps();
  meta["updates"] = algorithm_->updates();
  meta["wall_time_s"] = elapsed_s();
  std::vector<double> recent;
  std::vector<std::int64_t> ended;
  for (const auto& [steps, value] : returns_) {
    ended.push_back(steps);
    recent.push_back(value);
  }
  meta["recent_returns"] = recent;
  meta["recent_return_steps"] = ended;
  // Where the envs are, for a resume to check its replay of the actions below against.
  meta["env_digest"] = loop_->digest();
  blobs["meta"] = meta.dump();
  // The envs' state, as the actions that led to it; none when the log does not go back to the
  // first reset.
  if (env_log_complete_) blobs["env_actions"] = loop_->action_log();
  last_checkpoint_ = run_->checkpoint_path(algorithm_->updates());
  write_checkpoint(last_checkpoint_, blobs);
  prune_checkpoints(run_->path(), settings_.keep_checkpoints);
}

json TrainingRun::evaluate_and_summarize() {
  const fs::path video = run_->path() / "final.mp4";
  EvaluationRequest request;
  request.episodes = settings_.eval_episodes;
  request.seed = settings_.seed() + kEvaluationSeedOffset;
  request.video = video;
  std::string note;
  if (cost_ && time_limit_s_ > 0.0) {
    // What the time left holds, at least one episode; then another only while one fits.
    const FinalEvaluationPlan plan =
        plan_final_evaluation(time_limit_s_ - elapsed_s(), *cost_, settings_.eval_episodes);
    request.episodes = plan.episodes;
    if (!plan.video) request.video.reset();
    note = plan.note;
    if (!note.empty()) {
      output_.out << "final evaluation: " << note << std::endl;
      progress_->wrote_line();
    }
  }
  std::optional<std::chrono::steady_clock::time_point> first_plain;
  if (cost_ && time_limit_s_ > 0.0) {
    request.more = [&](std::int64_t done) {
      const auto now = std::chrono::steady_clock::now();
      if (!first_plain) first_plain = now;
      const double next = done >= 2 ? seconds_since(*first_plain) / static_cast<double>(done - 1)
                                    : cost_->episode_seconds(false);
      return elapsed_s() + next <= time_limit_s_;
    };
  }
  const auto eval_start = std::chrono::steady_clock::now();
  request.on_step = [&] {
    progress_->tick_note("final evaluation: " + one_decimal(seconds_since(eval_start)) +
                         " s so far");
  };
  std::error_code ignored;
  if (!request.video) fs::remove(video, ignored);  // a previous process's, not of this policy
  const PolicyEvaluation evaluation = evaluate(algorithm_->actor(), settings_, request);
  const auto played = static_cast<std::int64_t>(evaluation.returns.size());
  if (played < request.episodes) {
    const std::string cut = std::to_string(played) + " of " + std::to_string(request.episodes) +
                            " episodes: the time budget held no more";
    note += (note.empty() ? "" : "; ") + cut;
    output_.out << "final evaluation: " << cut << std::endl;
  }
  json summary;
  summary["env_id"] = settings_.env_id;
  summary["env_steps"] = algorithm_->env_steps();
  summary["updates"] = algorithm_->updates();
  summary["wall_time_s"] = elapsed_s();
  summary["stopped_by"] = stopped_by_;
  summary["evaluation"] = evaluation_json(evaluation, request);
  if (played < settings_.eval_episodes)
    summary["evaluation"]["episodes_asked"] = settings_.eval_episodes;
  summary["video"] = request.video ? json(video.filename().string()) : json(nullptr);
  if (evaluations_skipped_ > 0) summary["evaluations_skipped"] = evaluations_skipped_;
  if (time_limit_s_ > 0.0) {
    json budget = {{"minutes", budget_minutes_}, {"limit_s", time_limit_s_}};
    if (cost_) {
      budget["evaluation_episode_s"] = cost_->episode_seconds(false);
      budget["evaluation_video_episode_s"] = cost_->episode_seconds(true);
      budget["evaluation_reserved_s"] = time_limit_s_ - kCheckpointMarginS - training_deadline_s_;
      budget["training_deadline_s"] = training_deadline_s_;
    }
    budget["final_evaluation"] = note.empty() ? json("as asked") : json(note);
    summary["time_budget"] = budget;
  }
  if (distributed()) {
    json digests = json::array();
    for (const std::uint64_t digest : parameter_digests_) digests.push_back(hex_digest(digest));
    summary["distributed"] = {{"world_size", communicator_->world_size()},
                              {"parameter_digests", digests}};
  }
  run_->write_summary(summary);
  output_.out << "evaluation: return " << evaluation.mean << " +/- " << evaluation.std << " over "
              << evaluation.returns.size() << " episodes\n"
              << "wrote " << run_->path().string() << "/{config.json, progress.csv, curve.png, "
              << run_->checkpoint_path(algorithm_->updates()).filename().string()
              << (request.video ? ", final.mp4" : "") << ", summary.json}" << std::endl;
  return summary;
}

}  // namespace pixelgym::trainer
