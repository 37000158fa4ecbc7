// An Algorithm written outside pixelgym's tree, against the installed run library
// (find_package(pixelgym), pixelgym::trainer_run): a linear policy on CartPoleBalance-v1's state
// (action = clamp(w . [joint_pos, joint_vel] + b, -1, 1)), improved by random search: each
// iteration plays a perturbed copy of the best weights, which becomes the best when its episodes
// returned more. trainer::TrainingRun trains it for a few hundred env steps into a run folder
// (config.json, progress.csv with this algorithm's metrics, checkpoints, evaluation, summary.json),
// then resumes it from its checkpoint for more.
#include <pixelgym/envs/params.h>
#include <pixelgym/trainer/algorithm.h>
#include <pixelgym/trainer/progress_csv.h>
#include <pixelgym/trainer/training_run.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using nlohmann::json;
using namespace pixelgym;
using namespace pixelgym::trainer;

constexpr int kWeights = 5;  // joint_pos (2), joint_vel (2), bias

// The linear policy's actions for a batch of state observations.
void linear_actions(const std::vector<double>& weights, const Value& observations, Value& actions) {
  const Array& position = observations.dict().at("joint_pos").array();
  const Array& velocity = observations.dict().at("joint_vel").array();
  Array& action = actions.array();
  const std::int64_t envs = action.shape()[0];
  for (std::int64_t i = 0; i < envs; ++i) {
    const float* p = position.data<float>() + 2 * i;
    const float* v = velocity.data<float>() + 2 * i;
    const double a =
        weights[0] * p[0] + weights[1] * p[1] + weights[2] * v[0] + weights[3] * v[1] + weights[4];
    action.data<float>()[i] = static_cast<float>(std::clamp(a, -1.0, 1.0));
  }
}

class LinearActor final : public Actor {
 public:
  explicit LinearActor(const std::vector<double>& weights) : weights_(weights) {}
  ActCounts act(const Value& observations, bool /*deterministic*/, Value& actions) override {
    linear_actions(weights_, observations, actions);
    return {0, actions.array().shape()[0]};
  }

 private:
  const std::vector<double>& weights_;
};

class RandomSearch final : public Algorithm {
 public:
  RandomSearch(EnvLoop& loop, const json& config)
      : loop_(loop),
        steps_per_iteration_(config.at("steps_per_iteration").get<std::int64_t>()),
        rng_(config.at("seed").get<std::uint64_t>()),
        best_(kWeights, 0.0),
        candidate_(kWeights, 0.0),
        actions_(loop.zero_actions()),
        actor_(best_) {
    propose();
  }

  IterationStats iterate(const StopCheck& stop) override {
    IterationStats stats;
    // The run's env loop resets the envs with the run's seed, logs the actions (a resume
    // replays them) and records the episodes.
    if (!loop_.started()) loop_.reset();
    for (std::int64_t k = 0; k < steps_per_iteration_; ++k) {
      linear_actions(candidate_, loop_.observations(), actions_);
      for (const double r : loop_.ended_returns(loop_.step(actions_))) {
        stats.episode_returns.push_back(r);
      }
      ++batches_;
      if (stop && stop(env_steps())) break;
    }
    double mean = -1e300;
    if (!stats.episode_returns.empty()) {
      mean = 0.0;
      for (const double r : stats.episode_returns) mean += r;
      mean /= static_cast<double>(stats.episode_returns.size());
    }
    if (mean > best_return_) {
      best_return_ = mean;
      best_ = candidate_;
    }
    propose();
    ++updates_;
    // No episode ended yet: no figure (an empty field).
    const auto figure = [](double r) { return r > -1e300 ? r : ProgressRow::kNone; };
    stats.metrics = {{"best_return", figure(best_return_)}, {"candidate_return", figure(mean)}};
    return stats;
  }
  std::int64_t env_steps() const override { return batches_ * loop_.num_envs(); }
  std::int64_t updates() const override { return updates_; }
  void set_progress(std::int64_t env_steps, std::int64_t updates) override {
    batches_ = env_steps / loop_.num_envs();
    updates_ = updates;
  }
  std::vector<std::string> metric_names() const override {
    return {"best_return", "candidate_return"};
  }
  void save(CheckpointBlobs& blobs, json& meta) override {
    std::ostringstream rng;
    rng << rng_;
    blobs["random_search"] = json{
        {"best", best_},
        {"candidate", candidate_},
        {"best_return", best_return_},
        {"rng", rng.str()}}.dump();
    meta["random_search_best_return"] = best_return_;
  }
  void restore(const LoadedCheckpoint& checkpoint, const json& /*meta*/) override {
    const auto found = checkpoint.blobs.find("random_search");
    if (found == checkpoint.blobs.end()) {
      throw std::runtime_error(checkpoint.path.string() + ": no \"random_search\" blob");
    }
    const json state = json::parse(found->second);
    best_ = state.at("best").get<std::vector<double>>();
    candidate_ = state.at("candidate").get<std::vector<double>>();
    best_return_ = state.at("best_return").get<double>();
    std::istringstream rng(state.at("rng").get<std::string>());
    rng >> rng_;
  }
  Actor& actor() override { return actor_; }

 private:
  void propose() {
    std::normal_distribution<double> noise(0.0, 0.5);
    for (int i = 0; i < kWeights; ++i) candidate_[i] = best_[i] + noise(rng_);
  }
  EnvLoop& loop_;
  std::int64_t steps_per_iteration_;
  std::mt19937_64 rng_;
  std::vector<double> best_;
  std::vector<double> candidate_;
  double best_return_ = -1e300;
  Value actions_;
  std::int64_t batches_ = 0;
  std::int64_t updates_ = 0;
  LinearActor actor_;
};

class RandomSearchFactory final : public AlgorithmFactory {
 public:
  std::string name() const override { return "random_search"; }
  json parse_config(const std::string& text) const override {
    json config = {
        {"seed", 0}, {"num_envs", 2}, {"total_env_steps", 400}, {"steps_per_iteration", 25}};
    const json given = json::parse(text);
    for (const auto& [key, value] : given.items()) {
      if (!config.contains(key)) throw std::invalid_argument("random_search: unknown " + key);
      config[key] = value;
    }
    return config;
  }
  int set_threads(int requested) const override { return requested == 0 ? 1 : requested; }
  std::unique_ptr<Algorithm> make(EnvLoop& loop, const json& config,
                                  Communicator& communicator) const override {
    if (communicator.world_size() != 1) throw std::invalid_argument("random_search: one process");
    return std::make_unique<RandomSearch>(loop, config);
  }
  std::unique_ptr<Actor> load_actor(const Space&, const Space&, const json&,
                                    const LoadedCheckpoint&) const override {
    throw std::invalid_argument("random_search: evaluates only within its run");
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: own_algorithm RUN_FOLDER\n";
    return 2;
  }
  const std::filesystem::path folder = argv[1];
  std::filesystem::remove_all(folder);
  const RandomSearchFactory factory;
  RunSettings settings;
  settings.env_id = "CartPoleBalance-v1";
  settings.env_kwargs = {{"obs_mode", "state"},
                         {"max_episode_steps", 50},
                         {"render_width", 32},
                         {"render_height", 32}};
  settings.num_threads = 1;
  settings.checkpoint_every = 4;
  settings.keep_checkpoints = 1;
  settings.eval_episodes = 2;
  settings.algorithm_config = factory.parse_config(R"({"seed": 3})");
  std::optional<json> summary =
      TrainingRun::create(factory, settings, folder, TrainBudget{}, RunOutput{std::cout, std::cerr})
          .train();
  if (!summary) throw std::runtime_error("the new run returned no summary");
  const ProgressTable progress = read_progress_csv(folder / "progress.csv");
  std::cout << "own algorithm trained: " << progress.rows.size() << " rows, last best_return "
            << progress.column("best_return").back() << ", evaluation return_mean "
            << summary->at("evaluation").at("return_mean").get<double>() << "\n";

  summary = TrainingRun::resume(factory, folder, TrainBudget{600, 0.0}, ResumeChecks{},
                                RunOutput{std::cout, std::cerr})
                .train();
  if (!summary) throw std::runtime_error("the resumed run returned no summary");
  std::cout << "own algorithm resumed to " << summary->at("env_steps").get<std::int64_t>()
            << " env steps\n";
  std::cout << "own algorithm ran to the end\n";
  return 0;
}
