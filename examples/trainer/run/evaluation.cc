#include "pixelgym/trainer/evaluation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/time_limit.h"
#include "pixelgym/envs/vector/sync_vector_env.h"
#include "pixelgym/envs/wrapper.h"
#include "pixelgym/wrappers/record_video.h"

namespace pixelgym::trainer {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using Clock = std::chrono::steady_clock;

// Steps played before the cost of an evaluation step is timed.
constexpr std::int64_t kWarmUpSteps = 5;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// One episode of `actor` from `seed` to its end (or `max_steps`, when > 0); returns its return
// and adds its steps to `steps`.
double play_episode(Actor& actor, vector::VectorEnv& env, std::uint64_t seed, bool deterministic,
                    Value& actions, ActCounts& counts, std::int64_t& steps,
                    const std::function<void()>& on_step, std::int64_t max_steps = 0) {
  const Value* obs = &env.reset(seed).obs;
  double total = 0.0;
  for (std::int64_t t = 0; max_steps <= 0 || t < max_steps; ++t) {
    const ActCounts step_counts = actor.act(*obs, deterministic, actions);
    counts.clipped_elements += step_counts.clipped_elements;
    counts.float_elements += step_counts.float_elements;
    const vector::VectorStepResult& step = env.step(actions);
    ++steps;
    if (on_step) on_step();
    total += step.rewards.data<double>()[0];
    obs = &step.obs;
    if (step.terminated.data<bool>()[0] || step.truncated.data<bool>()[0]) return total;
  }
  return total;
}

// The shortest max_episode_steps of the TimeLimits around `env`'s core; 0 when there is none.
std::int64_t time_limit_of(Env& env) {
  std::int64_t limit = 0;
  Env* layer = &env;
  while (auto* wrapper = dynamic_cast<Wrapper*>(layer)) {
    if (const auto* time_limit = dynamic_cast<const TimeLimit*>(wrapper)) {
      const std::int64_t steps = time_limit->max_episode_steps();
      limit = limit == 0 ? steps : std::min(limit, steps);
    }
    layer = &wrapper->env();
  }
  return limit;
}

// A vector env of one env built as the run's, recorded through `recorder` when `video_folder`
// is given.
std::unique_ptr<vector::SyncVectorEnv> evaluation_env(const RunSettings& settings,
                                                      const std::optional<fs::path>& video_folder,
                                                      wrappers::RecordVideo*& recorder,
                                                      std::int64_t* time_limit = nullptr) {
  recorder = nullptr;
  const vector::EnvFactory factory = [&](int) {
    std::unique_ptr<Env> env = make_run_env(settings);
    if (time_limit != nullptr) *time_limit = time_limit_of(*env);
    if (!video_folder) return env;
    auto recorded = std::make_unique<wrappers::RecordVideo>(
        std::move(env), *video_folder, [](std::int64_t) { return false; }, nullptr, 0, "eval");
    recorder = recorded.get();
    return std::unique_ptr<Env>(std::move(recorded));
  };
  return std::make_unique<vector::SyncVectorEnv>(1, factory, vector::AutoresetMode::kDisabled);
}

// The checkpoint `run_or_checkpoint` names (see evaluate_checkpoint) and the folder of its run.
std::pair<LoadedCheckpoint, fs::path> find_checkpoint(const fs::path& run_or_checkpoint,
                                                      const std::string& command,
                                                      std::ostream& errors) {
  if (!fs::exists(run_or_checkpoint)) {
    throw std::runtime_error(command + ": " + run_or_checkpoint.string() +
                             " does not exist; expected a run folder (`pixelgym train --out`'s) "
                             "or a checkpoint file (ckpt-*.pgck)");
  }
  if (!fs::is_directory(run_or_checkpoint)) {
    const fs::path folder =
        run_or_checkpoint.parent_path().empty() ? fs::path(".") : run_or_checkpoint.parent_path();
    LoadedCheckpoint checkpoint{
        run_or_checkpoint, checkpoint_update(run_or_checkpoint.filename().string()).value_or(0),
        read_checkpoint(run_or_checkpoint)};
    return {std::move(checkpoint), folder};
  }
  CheckpointSearch search = find_latest_checkpoint(run_or_checkpoint);
  for (const auto& skipped : search.skipped) {
    errors << command << ": skipping " << skipped.path.string() << ": " << skipped.reason << "\n";
  }
  if (!search.latest && search.skipped.empty() && !fs::exists(run_or_checkpoint / "config.json")) {
    throw std::runtime_error(command + ": " + run_or_checkpoint.string() +
                             " is not a run folder (no checkpoint ckpt-*.pgck, config.json or "
                             "summary.json in it)");
  }
  if (!search.latest) {
    throw std::runtime_error(command + ": no valid checkpoint in " + run_or_checkpoint.string());
  }
  return {std::move(*search.latest), run_or_checkpoint};
}

// The settings `checkpoint` carries (a checkpoint file copied anywhere evaluates), else its run
// folder's config.json.
// The run's settings and its algorithm.
std::pair<RunSettings, const AlgorithmFactory*> checkpoint_settings(
    const LoadedCheckpoint& checkpoint, const fs::path& folder,
    const AlgorithmFactories& algorithms, const std::string& command) {
  const auto read = [&](const json& config, const fs::path& where) {
    const AlgorithmFactory& algorithm = algorithm_of(config, where, algorithms);
    return std::make_pair(settings_from_json(config, where, algorithm), &algorithm);
  };
  if (const auto embedded = checkpoint.blobs.find("config"); embedded != checkpoint.blobs.end()) {
    return read(json::parse(embedded->second), checkpoint.path);
  }
  if (!fs::exists(folder / "config.json")) {
    throw std::runtime_error(command + ": " + checkpoint.path.string() +
                             " does not carry its run's settings, and there is no config.json "
                             "in " +
                             folder.string() + " (the run folder it belongs to)");
  }
  return read(read_run_config(folder / "config.json", command), folder / "config.json");
}

// The policy of `checkpoint`, loaded by `algorithm` for an env built as the run's, computing
// with the run's torch threads.
std::unique_ptr<Actor> load_run_actor(const AlgorithmFactory& algorithm,
                                      const RunSettings& settings,
                                      const LoadedCheckpoint& checkpoint) {
  algorithm.set_threads(settings.torch_threads);
  // The spaces come from one env built as the run's.
  std::unique_ptr<Env> probe = make_run_env(settings);
  std::unique_ptr<Actor> actor = algorithm.load_actor(
      probe->observation_space(), probe->action_space(), settings.algorithm_config, checkpoint);
  probe->close();
  return actor;
}

}  // namespace

PolicyEvaluation evaluate(Actor& actor, const RunSettings& settings,
                          const EvaluationRequest& request) {
  const std::optional<fs::path>& video = request.video;
  std::optional<fs::path> video_folder;
  if (video) video_folder = video->parent_path().empty() ? fs::path(".") : video->parent_path();
  wrappers::RecordVideo* recorder = nullptr;
  const std::unique_ptr<vector::SyncVectorEnv> made =
      evaluation_env(settings, video_folder, recorder);
  vector::SyncVectorEnv& env = *made;
  Value actions = env.action_space().zeros();
  PolicyEvaluation result;
  ActCounts counts;
  for (std::int64_t e = 0; e < request.episodes; ++e) {
    if (e > 0 && request.more && !request.more(e)) break;
    const auto episode_start = Clock::now();
    if (e == 0 && recorder != nullptr) recorder->start_recording(video->stem().string());
    result.returns.push_back(play_episode(actor, env, request.seed + static_cast<std::uint64_t>(e),
                                          !request.stochastic, actions, counts, result.steps,
                                          request.on_step));
    if (e == 0 && recorder != nullptr) recorder->stop_recording();
    result.episode_s.push_back(seconds_since(episode_start));
  }
  double sum = 0.0;
  for (const double r : result.returns) sum += r;
  result.mean = sum / static_cast<double>(result.returns.size());
  double squares = 0.0;
  for (const double r : result.returns) squares += (r - result.mean) * (r - result.mean);
  result.std = std::sqrt(squares / static_cast<double>(result.returns.size()));
  if (counts.float_elements > 0) {
    result.clipped_fraction =
        static_cast<double>(counts.clipped_elements) / static_cast<double>(counts.float_elements);
  }
  env.close();
  return result;
}

double EvaluationCost::episode_seconds(bool video) const {
  const auto steps = static_cast<double>(episode_steps);
  return video ? video_fixed_s + steps * video_step_s : steps * step_s;
}

double EvaluationCost::evaluation_seconds(std::int64_t episodes, bool video) const {
  if (episodes <= 0) return 0.0;
  return setup_s + episode_seconds(video) +
         static_cast<double>(episodes - 1) * episode_seconds(false);
}

EvaluationCost measure_evaluation_cost(Actor& actor, const RunSettings& settings,
                                       const fs::path& scratch_folder, std::int64_t steps,
                                       const std::function<void()>& on_step) {
  EvaluationCost cost;
  const auto setup_start = Clock::now();
  wrappers::RecordVideo* recorder = nullptr;
  std::int64_t time_limit = 0;
  const std::unique_ptr<vector::SyncVectorEnv> made =
      evaluation_env(settings, scratch_folder, recorder, &time_limit);
  vector::SyncVectorEnv& env = *made;
  Value actions = env.action_space().zeros();
  cost.setup_s = seconds_since(setup_start);
  if (time_limit > 0) {
    cost.episode_steps = time_limit;
    cost.episode_steps_known = true;
  }
  ActCounts counts;
  // Untimed: the first steps warm the policy and the renderer up.
  std::int64_t warm = 0;
  play_episode(actor, env, settings.seed() + kEvaluationSeedOffset, true, actions, counts, warm,
               on_step, kWarmUpSteps);
  std::int64_t played = 0;
  auto start = Clock::now();
  while (played < steps) {
    play_episode(actor, env, settings.seed() + kEvaluationSeedOffset, true, actions, counts, played,
                 on_step, steps - played);
  }
  cost.step_s = seconds_since(start) / static_cast<double>(played);
  // Recorded: the first step opens the video file and the last finishes it (fixed costs); the
  // steps between are the per-step cost.
  const std::string scratch = ".evaluation_cost_probe";
  recorder->start_recording(scratch);
  start = Clock::now();
  std::int64_t recorded = 0;
  play_episode(actor, env, settings.seed() + kEvaluationSeedOffset, true, actions, counts, recorded,
               on_step, 1);
  const double first_s = seconds_since(start);
  start = Clock::now();
  const std::int64_t more = std::max<std::int64_t>(steps - 1, 1);
  std::int64_t later = 0;
  while (later < more) {
    play_episode(actor, env, settings.seed() + kEvaluationSeedOffset, true, actions, counts, later,
                 on_step, more - later);
  }
  // A recorded step costs what a plain one does and more (the timings of a busy machine may say
  // otherwise).
  cost.video_step_s = std::max(seconds_since(start) / static_cast<double>(later), cost.step_s);
  start = Clock::now();
  recorder->stop_recording();
  cost.video_fixed_s = std::max(0.0, first_s - cost.video_step_s) + seconds_since(start);
  env.close();
  std::error_code ignored;
  fs::remove(scratch_folder / (scratch + ".mp4"), ignored);
  return cost;
}

FinalEvaluationPlan plan_final_evaluation(double seconds, const EvaluationCost& cost,
                                          std::int64_t asked) {
  FinalEvaluationPlan plan;
  const auto fitting = [&](bool video) {
    std::int64_t episodes = asked;
    while (episodes > 1 && cost.evaluation_seconds(episodes, video) > seconds) --episodes;
    return episodes;
  };
  const auto plural = [](std::int64_t n) { return n == 1 ? " episode" : " episodes"; };
  std::ostringstream note;
  note.precision(2);
  note << std::fixed;
  if (cost.evaluation_seconds(1, true) <= seconds) {
    plan.video = true;
    plan.episodes = fitting(true);
  } else {
    plan.video = false;
    plan.episodes = fitting(false);
    note << "no final.mp4 (one recorded episode takes about " << cost.evaluation_seconds(1, true)
         << " s, more than the " << std::max(seconds, 0.0) << " s the time budget leaves it)";
  }
  if (plan.episodes < asked) {
    if (!note.str().empty()) note << "; ";
    note << plan.episodes << " of --eval-episodes " << asked << plural(asked) << " (about "
         << cost.episode_seconds(false) << " s each at most, "
         << cost.evaluation_seconds(plan.episodes, plan.video) << " s in all"
         << (cost.evaluation_seconds(plan.episodes, plan.video) > seconds ? ", more than the "
                                                                          : " of the ")
         << std::max(seconds, 0.0) << " s the time budget leaves)";
  }
  plan.seconds = cost.evaluation_seconds(plan.episodes, plan.video);
  plan.note = note.str();
  return plan;
}

json evaluation_json(const PolicyEvaluation& evaluation, const EvaluationRequest& request) {
  json out;
  out["episodes"] = evaluation.returns.size();
  out["seed"] = request.seed;
  out["deterministic"] = !request.stochastic;
  out["return_mean"] = evaluation.mean;
  out["return_std"] = evaluation.std;
  out["returns"] = evaluation.returns;
  out["clipped_action_fraction"] = evaluation.clipped_fraction;
  return out;
}

CheckpointEvaluation evaluate_checkpoint(const AlgorithmFactories& algorithms,
                                         const fs::path& run_or_checkpoint,
                                         const CheckpointEvaluationRequest& given,
                                         std::ostream& errors) {
  const auto [checkpoint, folder] = find_checkpoint(run_or_checkpoint, "eval", errors);
  auto [settings, found] = checkpoint_settings(checkpoint, folder, algorithms, "eval");
  const AlgorithmFactory& algorithm = *found;
  CheckpointEvaluation result{checkpoint.path, std::move(settings), {}, {}, {}};
  // The run's final evaluation: summary.json's when it is of this checkpoint (the same env
  // steps), else the run's settings.
  EvaluationRequest& request = result.request;
  request.episodes = result.settings.eval_episodes;
  request.seed = result.settings.seed() + kEvaluationSeedOffset;
  result.defaults_from = "the run's settings";
  std::ifstream summary_file(folder / "summary.json");
  const json summary = summary_file ? json::parse(summary_file, nullptr, false) : json();
  const auto meta = checkpoint.blobs.find("meta");
  if (summary.is_object() && summary.contains("evaluation") && meta != checkpoint.blobs.end() &&
      json::parse(meta->second, nullptr, false).value("env_steps", std::int64_t{-1}) ==
          summary.value("env_steps", std::int64_t{-2})) {
    const json& evaluation = summary.at("evaluation");
    request.episodes = evaluation.value("episodes", request.episodes);
    request.seed = evaluation.value("seed", request.seed);
    result.defaults_from = "summary.json";
  }
  if (given.episodes) request.episodes = *given.episodes;
  if (given.seed) request.seed = *given.seed;
  request.stochastic = given.stochastic;
  request.video = given.video;
  const std::unique_ptr<Actor> actor = load_run_actor(algorithm, result.settings, checkpoint);
  if (given.env_id || !given.env_sets.empty()) {
    // Another env, or other kwargs: the policy reads the run's spaces, so these must be the same.
    const std::unique_ptr<Env> run_env = make_run_env(result.settings);
    const std::string run_id = result.settings.env_id;
    if (given.env_id) result.settings.env_id = *given.env_id;
    for (auto& [key, value] : parse_kwargs(result.settings.env_id, given.env_sets)) {
      result.settings.env_kwargs.insert_or_assign(key, value);
    }
    const std::unique_ptr<Env> played = make_run_env(result.settings);
    for (const auto& [what, ours, theirs] :
         {std::tuple<const char*, const Space*, const Space*>{
              "observation", &played->observation_space(), &run_env->observation_space()},
          {"action", &played->action_space(), &run_env->action_space()}}) {
      if (!ours->equals(*theirs)) {
        throw std::runtime_error("eval: " + result.settings.env_id + "'s " + what + " space " +
                                 ours->to_string() + " is not the run's (" + run_id + ": " +
                                 theirs->to_string() + "); the policy reads the run's");
      }
    }
    run_env->close();
    played->close();
  }
  result.evaluation = evaluate(*actor, result.settings, request);
  return result;
}

CheckpointPolicy load_checkpoint_policy(const AlgorithmFactories& algorithms,
                                        const fs::path& run_or_checkpoint,
                                        const std::string& command, std::ostream& errors) {
  const auto [checkpoint, folder] = find_checkpoint(run_or_checkpoint, command, errors);
  auto [settings, algorithm] = checkpoint_settings(checkpoint, folder, algorithms, command);
  CheckpointPolicy result{checkpoint.path, std::move(settings), 0, nullptr};
  if (const auto meta = checkpoint.blobs.find("meta"); meta != checkpoint.blobs.end()) {
    result.env_steps =
        json::parse(meta->second, nullptr, false).value("env_steps", std::int64_t{0});
  }
  result.actor = load_run_actor(*algorithm, result.settings, checkpoint);
  return result;
}

}  // namespace pixelgym::trainer
