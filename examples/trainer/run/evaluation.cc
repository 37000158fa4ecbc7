#include "examples/trainer/run/evaluation.h"

#include <cmath>
#include <memory>
#include <stdexcept>
#include <utility>

#include "pixelgym/envs/vector/sync_vector_env.h"
#include "pixelgym/wrappers/record_video.h"

namespace pixelgym::trainer {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// One episode of `actor` from `seed` to its end; returns its return.
double play_episode(Actor& actor, vector::VectorEnv& env, std::uint64_t seed, bool deterministic,
                    Value& actions, ActCounts& counts) {
  const Value* obs = &env.reset(seed).obs;
  double total = 0.0;
  for (;;) {
    const ActCounts step_counts = actor.act(*obs, deterministic, actions);
    counts.clipped_elements += step_counts.clipped_elements;
    counts.float_elements += step_counts.float_elements;
    const vector::VectorStepResult& step = env.step(actions);
    total += step.rewards.data<double>()[0];
    obs = &step.obs;
    if (step.terminated.data<bool>()[0] || step.truncated.data<bool>()[0]) return total;
  }
}

// The checkpoint `run_or_checkpoint` names (see evaluate_checkpoint) and the folder of its run.
std::pair<LoadedCheckpoint, fs::path> find_checkpoint(const fs::path& run_or_checkpoint,
                                                      std::ostream& errors) {
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
    errors << "eval: skipping " << skipped.path.string() << ": " << skipped.reason << "\n";
  }
  if (!search.latest) {
    throw std::runtime_error("eval: no valid checkpoint in " + run_or_checkpoint.string());
  }
  return {std::move(*search.latest), run_or_checkpoint};
}

// The settings `checkpoint` carries (a checkpoint file copied anywhere evaluates), else its run
// folder's config.json.
// The run's settings and its algorithm.
std::pair<RunSettings, const AlgorithmFactory*> checkpoint_settings(
    const LoadedCheckpoint& checkpoint, const fs::path& folder,
    const AlgorithmFactories& algorithms) {
  const auto read = [&](const json& config, const fs::path& where) {
    const AlgorithmFactory& algorithm = algorithm_of(config, where, algorithms);
    return std::make_pair(settings_from_json(config, where, algorithm), &algorithm);
  };
  if (const auto embedded = checkpoint.blobs.find("config"); embedded != checkpoint.blobs.end()) {
    return read(json::parse(embedded->second), checkpoint.path);
  }
  if (!fs::exists(folder / "config.json")) {
    throw std::runtime_error("eval: " + checkpoint.path.string() +
                             " does not carry its run's settings, and there is no config.json "
                             "in " +
                             folder.string() + " (the run folder it belongs to)");
  }
  return read(read_run_config(folder / "config.json", "eval"), folder / "config.json");
}

}  // namespace

PolicyEvaluation evaluate(Actor& actor, const RunSettings& settings,
                          const EnvKwargsParser& parse_sets, const EvaluationRequest& request) {
  const std::optional<fs::path>& video = request.video;
  wrappers::RecordVideo* recorder = nullptr;
  const vector::EnvFactory factory = [&](int) {
    std::unique_ptr<Env> env = make_run_env(settings, parse_sets);
    if (!video) return env;
    const fs::path folder = video->parent_path().empty() ? fs::path(".") : video->parent_path();
    auto recorded = std::make_unique<wrappers::RecordVideo>(
        std::move(env), folder, [](std::int64_t) { return false; }, nullptr, 0, "eval");
    recorder = recorded.get();
    return std::unique_ptr<Env>(std::move(recorded));
  };
  vector::SyncVectorEnv env(1, factory, vector::AutoresetMode::kDisabled);
  Value actions = env.action_space().zeros();
  PolicyEvaluation result;
  ActCounts counts;
  for (std::int64_t e = 0; e < request.episodes; ++e) {
    if (e == 0 && recorder != nullptr) recorder->start_recording(video->stem().string());
    result.returns.push_back(play_episode(actor, env, request.seed + static_cast<std::uint64_t>(e),
                                          !request.stochastic, actions, counts));
    if (e == 0 && recorder != nullptr) recorder->stop_recording();
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
                                         const EnvKwargsParser& parse_sets,
                                         const fs::path& run_or_checkpoint,
                                         const EvaluationRequest& request, std::ostream& errors) {
  const auto [checkpoint, folder] = find_checkpoint(run_or_checkpoint, errors);
  auto [settings, found] = checkpoint_settings(checkpoint, folder, algorithms);
  const AlgorithmFactory& algorithm = *found;
  CheckpointEvaluation result{checkpoint.path, std::move(settings), {}};
  algorithm.set_threads(result.settings.torch_threads);
  // The spaces come from one env built as the run's.
  std::unique_ptr<Env> probe = make_run_env(result.settings, parse_sets);
  const std::unique_ptr<Actor> actor =
      algorithm.load_actor(probe->observation_space(), probe->action_space(),
                           result.settings.algorithm_config, checkpoint);
  probe->close();
  result.evaluation = evaluate(*actor, result.settings, parse_sets, request);
  return result;
}

}  // namespace pixelgym::trainer
