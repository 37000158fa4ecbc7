// TrainingRun driving an algorithm that is not PPO and needs no torch: a counting algorithm on
// GridWorld-v0 whose actions follow a fixed pattern, so that the run's budget, checkpoints,
// resume (replay of the env actions included), evaluation and summary can be checked exactly.
#include "pixelgym/trainer/training_run.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "pixelgym/envs/tasks/grid_world.h"
#include "pixelgym/trainer/checkpoint_file.h"
#include "pixelgym/trainer/progress_csv.h"
#include "tests/examples/trainer/run/test_folders.h"

namespace pixelgym::trainer {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Always GridWorld's action 1 (down): an episode stays in the left column until truncated
// after 50 steps, a return of 50 x -0.04.
class DownActor final : public Actor {
 public:
  ActCounts act(const Value& observations, bool deterministic, Value& actions) override {
    EXPECT_TRUE(deterministic);
    EXPECT_EQ(observations.array().shape()[0], 1);
    ++calls;
    if (sleep_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(sleep_ms));
    actions.array().data<std::int64_t>()[0] = 1;
    return {};
  }
  std::int64_t calls = 0;
  int sleep_ms = 0;  // a slow policy: evaluations take 50 x this per episode
};

// A pseudo-random action for env i at step t (SplitMix64 of t * 2 + i), down or right two times
// in three: walks that reach the goal after different numbers of steps, so that episode returns
// differ.
std::int64_t walk_action(std::int64_t t, int i) {
  std::uint64_t z = static_cast<std::uint64_t>(t * 2 + i) + 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  constexpr std::int64_t kMoves[] = {GridWorld::kDown,  GridWorld::kRight, GridWorld::kDown,
                                     GridWorld::kRight, GridWorld::kLeft,  GridWorld::kUp};
  return kMoves[(z ^ (z >> 31)) % 6];
}

// Steps the run's env loop steps_per_iteration times an iteration, env i taking walk_action(t, i)
// at step t (counted from the first reset); "learns" a counter of its iterations, saved in a blob
// "counter". Its metrics: policy_loss = the counter, and "counter" too.
class CountingAlgorithm final : public Algorithm {
 public:
  CountingAlgorithm(EnvLoop& loop, const json& config)
      : loop_(loop),
        steps_per_iteration_(config.at("steps_per_iteration").get<std::int64_t>()),
        actions_(loop.zero_actions()) {}

  IterationStats iterate(const StopCheck& stop) override {
    IterationStats stats;
    if (!loop_.started()) loop_.reset();
    for (std::int64_t k = 0; k < steps_per_iteration_; ++k) {
      auto* action = actions_.array().data<std::int64_t>();
      for (int i = 0; i < loop_.num_envs(); ++i) action[i] = walk_action(loop_.batches(), i);
      for (const double r : loop_.ended_returns(loop_.step(actions_))) {
        stats.episode_returns.push_back(r);
      }
      batches_ += 1;
      if (stop && stop(env_steps())) break;
    }
    counter_ += 1;
    updates_ += 1;
    stats.metrics = {{"policy_loss", static_cast<double>(counter_)},
                     {"counter", static_cast<double>(counter_)}};
    return stats;
  }
  std::int64_t env_steps() const override { return batches_ * loop_.num_envs(); }
  std::int64_t updates() const override { return updates_; }
  void set_progress(std::int64_t env_steps, std::int64_t updates) override {
    batches_ = env_steps / loop_.num_envs();
    updates_ = updates;
  }
  std::vector<std::string> metric_names() const override { return {"policy_loss", "counter"}; }
  void save(CheckpointBlobs& blobs, json& meta) override {
    blobs["counter"] = std::to_string(counter_);
    meta["counter"] = counter_;
  }
  void restore(const LoadedCheckpoint& checkpoint, const json& meta) override {
    counter_ = std::stoll(checkpoint.blobs.at("counter"));
    EXPECT_EQ(meta.at("counter"), counter_);
  }
  void replayed_reset(const Value& /*observations*/) override { replayed_ = 0; }
  void replayed_step(const Value& /*actions*/, const vector::VectorStepResult& /*step*/) override {
    replayed_ += 1;
  }
  Actor& actor() override { return actor_; }
  const EnvLoop& loop() const { return loop_; }
  // The steps the run replayed into it on resume.
  std::int64_t replayed() const { return replayed_; }

  DownActor actor_;

 private:
  EnvLoop& loop_;
  std::int64_t steps_per_iteration_;
  Value actions_;
  std::int64_t batches_ = 0;
  std::int64_t updates_ = 0;
  std::int64_t counter_ = 0;
  std::int64_t replayed_ = -1;
};

class CountingFactory final : public AlgorithmFactory {
 public:
  std::string name() const override { return "counting"; }
  json parse_config(const std::string& text) const override {
    json config = {
        {"seed", 0}, {"num_envs", 2}, {"total_env_steps", 40}, {"steps_per_iteration", 4}};
    const json given = json::parse(text);
    for (const auto& [key, value] : given.items()) {
      if (!config.contains(key)) throw std::invalid_argument("counting: unknown member " + key);
      config[key] = value;
    }
    if (config.at("total_env_steps").get<std::int64_t>() < 1) {
      throw std::invalid_argument("counting: total_env_steps must be >= 1");
    }
    return config;
  }
  int set_threads(int requested) const override { return requested == 0 ? 3 : requested; }
  std::unique_ptr<Algorithm> make(EnvLoop& loop, const json& config,
                                  Communicator& /*communicator*/) const override {
    auto algorithm = std::make_unique<CountingAlgorithm>(loop, config);
    algorithm->actor_.sleep_ms = actor_sleep_ms;
    last = algorithm.get();
    return algorithm;
  }
  std::unique_ptr<Actor> load_actor(const Space&, const Space&, const json&,
                                    const LoadedCheckpoint&) const override {
    return std::make_unique<DownActor>();
  }
  mutable CountingAlgorithm* last = nullptr;  // the latest made (valid while its run lives)
  int actor_sleep_ms = 0;                     // its actor's (DownActor::sleep_ms)
};

RunSettings grid_settings(std::int64_t checkpoint_every = 2, std::int64_t keep_checkpoints = 2) {
  const CountingFactory factory;
  RunSettings settings;
  settings.env_id = "GridWorld-v0";
  settings.env_kwargs = {{"render_width", 32}, {"render_height", 32}};
  settings.num_threads = 1;
  settings.checkpoint_every = checkpoint_every;
  settings.keep_checkpoints = keep_checkpoints;
  settings.eval_episodes = 2;
  settings.algorithm_config = factory.parse_config(R"({"seed": 7})");
  return settings;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A new run trains to its step budget (8 env steps an iteration: 5 iterations for 40), writes
// its rows with the algorithm's column, checkpoints every 2 updates and at the end keeping the
// newest 2, evaluates with the algorithm's actor and writes the summary.
// The episodes a progress row summarizes: the latest 100 at most, of those that ended within the
// last max(a tenth of the steps, the iteration's steps), and always the latest. Episodes of 250
// env steps over a 27,000-step run were all in the window (100 episodes), so the curve lagged
// the policy by the whole run.
TEST(TrainingRunTest, TheRecentEpisodesAreBoundedBySteps) {
  RecentReturns recent;
  for (std::int64_t step = 250; step <= 27000; step += 250) {
    add_recent_returns(recent, {static_cast<double>(step)}, step, 250);
  }
  // 2,700 steps: the episodes that ended from step 24,300 on.
  ASSERT_EQ(recent.size(), 11U);
  EXPECT_EQ(recent.front().first, 24500);
  EXPECT_EQ(recent.back().second, 27000.0);
  // Short episodes: 100 at most.
  RecentReturns short_ones;
  add_recent_returns(short_ones, std::vector<double>(300, 1.0), 1000, 1000);
  EXPECT_EQ(short_ones.size(), 100U);
  // An iteration longer than a tenth of the run keeps its episodes.
  RecentReturns long_iteration;
  add_recent_returns(long_iteration, {1.0, 2.0}, 1000, 1000);
  add_recent_returns(long_iteration, {3.0}, 2000, 1000);
  EXPECT_EQ(long_iteration.size(), 3U);
  // The latest episode stays, however long ago it ended.
  add_recent_returns(long_iteration, {}, 100000, 1000);
  ASSERT_EQ(long_iteration.size(), 1U);
  EXPECT_EQ(long_iteration.front().second, 3.0);
}

TEST(TrainingRunTest, ANewRunTrainsToItsStepBudgetAndWritesTheRunFolder) {
  const fs::path folder = test_folders::fresh_folder("training_run_new") / "run";
  const CountingFactory factory;
  std::ostringstream out;
  std::ostringstream errors;
  TrainingRun run =
      TrainingRun::create(factory, grid_settings(), folder, TrainBudget{}, RunOutput{out, errors});
  const std::optional<json> summary = run.train();
  ASSERT_TRUE(summary.has_value()) << out.str();

  const ProgressTable progress = read_progress_csv(folder / "progress.csv");
  EXPECT_EQ(progress.columns.back(), "counter");
  EXPECT_EQ(progress.column("steps"), (std::vector<double>{8, 16, 24, 32, 40}));
  EXPECT_EQ(progress.column("counter"), (std::vector<double>{1, 2, 3, 4, 5}));
  EXPECT_EQ(progress.column("policy_loss"), progress.column("counter"));
  EXPECT_EQ(
      test_folders::entries(folder),
      (std::vector<std::string>{".lock", "ckpt-000004.pgck", "ckpt-000005.pgck", "config.json",
                                "curve.png", "final.mp4", "progress.csv", "summary.json"}));
  const CheckpointBlobs blobs = read_checkpoint(folder / "ckpt-000005.pgck");
  EXPECT_EQ(blobs.at("counter"), "5");
  EXPECT_EQ(blobs.at("env_actions").size(), 20U * 2U * sizeof(std::int64_t));
  const json meta = json::parse(blobs.at("meta"));
  EXPECT_EQ(meta.at("env_steps"), 40);
  EXPECT_EQ(meta.at("updates"), 5);
  EXPECT_EQ(meta.at("counter"), 5);
  EXPECT_EQ(meta.at("env_digest"), factory.last->loop().digest());
  const json config = json::parse(read_text(folder / "config.json"));
  EXPECT_EQ(config.at("counting").at("seed"), 7);
  EXPECT_EQ(config.at("torch_threads"), 3);  // the count set_threads reported
  EXPECT_EQ(json::parse(blobs.at("config")).at("counting"), config.at("counting"));

  EXPECT_EQ(summary->at("env_steps"), 40);
  EXPECT_EQ(summary->at("updates"), 5);
  const json& evaluation = summary->at("evaluation");
  EXPECT_EQ(evaluation.at("seed"), 1'000'007);
  EXPECT_EQ(evaluation.at("returns").size(), 2U);
  EXPECT_NEAR(evaluation.at("return_mean").get<double>(), -2.0, 1e-9);
  EXPECT_EQ(factory.last->actor_.calls, 100);  // 2 truncated episodes of 50 steps
  EXPECT_EQ(json::parse(read_text(folder / "summary.json")), *summary);
  EXPECT_GT(fs::file_size(folder / "final.mp4"), 0U);
  EXPECT_NE(out.str().find("evaluation: return -2 +/- 0 over 2 episodes"), std::string::npos)
      << out.str();
}

// Evaluations during training go to eval.csv, one row each; while they have taken more than
// eval_max_share of the process's time, the next is skipped and the output says so. Here
// training is instant and an evaluation takes 100 ms: with share 1 every evaluation runs, with
// share 0.1 only the first does.
TEST(TrainingRunTest, EvaluationsDuringTrainingKeepToTheirShareOfTheTime) {
  const auto evaluations = [](double share, std::string* output) {
    const fs::path folder = test_folders::fresh_folder("training_run_eval_share") / "run";
    CountingFactory factory;
    factory.actor_sleep_ms = 2;
    RunSettings settings = grid_settings(100);
    settings.eval_every = 8;  // every iteration
    settings.eval_every_episodes = 1;
    settings.eval_max_share = share;
    std::ostringstream out;
    std::ostringstream errors;
    TrainingRun run =
        TrainingRun::create(factory, settings, folder, TrainBudget{}, RunOutput{out, errors});
    EXPECT_TRUE(run.train().has_value()) << out.str();
    *output = out.str();
    std::ifstream csv(folder / "eval.csv");
    std::string line;
    std::vector<std::string> steps;
    std::getline(csv, line);  // the header
    while (std::getline(csv, line)) steps.push_back(line.substr(0, line.find(',')));
    return steps;
  };
  std::string output;
  EXPECT_EQ(evaluations(1.0, &output), (std::vector<std::string>{"8", "16", "24", "32", "40"}));
  EXPECT_EQ(output.find("skipped"), std::string::npos) << output;
  EXPECT_EQ(evaluations(0.1, &output), (std::vector<std::string>{"8"}));
  EXPECT_NE(output.find("eval at 16 env steps skipped: evaluations took "), std::string::npos)
      << output;
}

// Stopped by its budget at 96 env steps and resumed to 192, a run is the run that trained to 192
// at once: the same rows (returns over episodes from before the stop included), the same learned
// state, the same envs (no digest warning).
TEST(TrainingRunTest, AResumedRunIsTheRunThatDidNotStop) {
  const fs::path base = test_folders::fresh_folder("training_run_resume");
  const CountingFactory factory;
  std::ostringstream out;
  std::ostringstream errors;
  RunSettings settings = grid_settings(3, 0);
  settings.algorithm_config["steps_per_iteration"] = 16;  // 32 env steps an iteration
  settings.env_kwargs.insert_or_assign("max_episode_steps",
                                       12);  // episodes end, at the goal or truncated
  TrainingRun whole =
      TrainingRun::create(factory, settings, base / "whole", TrainBudget{192, 0.0}, {out, errors});
  ASSERT_TRUE(whole.train().has_value());
  TrainingRun first =
      TrainingRun::create(factory, settings, base / "stopped", TrainBudget{96, 0.0}, {out, errors});
  ASSERT_TRUE(first.train().has_value());
  std::ostringstream resumed_out;
  TrainingRun resumed = TrainingRun::resume(factory, base / "stopped", TrainBudget{192, 0.0}, {},
                                            {resumed_out, errors});
  ASSERT_TRUE(resumed.train().has_value());
  EXPECT_NE(resumed_out.str().find("resuming " + (base / "stopped").string() +
                                   " from ckpt-000003.pgck (96 env steps, 3 updates)"),
            std::string::npos)
      << resumed_out.str();
  EXPECT_NE(resumed_out.str().find("replayed the 96 env steps of the checkpoint"),
            std::string::npos)
      << resumed_out.str();
  EXPECT_EQ(resumed_out.str().find("warning: the replayed envs"), std::string::npos)
      << resumed_out.str();
  // The run replayed the log through its loop and gave the algorithm each of its 48 batches.
  EXPECT_EQ(factory.last->replayed(), 48);

  const ProgressTable a = read_progress_csv(base / "whole" / "progress.csv");
  const ProgressTable b = read_progress_csv(base / "stopped" / "progress.csv");
  // Episodes ended before the stop, and their returns differ: the window of returns matters.
  ASSERT_EQ(a.rows.size(), 6U);
  EXPECT_GT(a.column("episode_return_std")[2], 0.0);
  for (const char* column : {"steps", "episode_return_mean", "episode_return_std", "counter"}) {
    const std::vector<double> x = a.column(column);
    const std::vector<double> y = b.column(column);
    ASSERT_EQ(x.size(), 6U) << column;
    ASSERT_EQ(y.size(), 6U) << column;
    for (std::size_t row = 0; row < x.size(); ++row) {
      EXPECT_TRUE(x[row] == y[row] || (std::isnan(x[row]) && std::isnan(y[row])))
          << column << " row " << row << ": " << x[row] << " vs " << y[row];
    }
  }
  const CheckpointBlobs x = read_checkpoint(base / "whole" / "ckpt-000006.pgck");
  const CheckpointBlobs y = read_checkpoint(base / "stopped" / "ckpt-000006.pgck");
  for (const char* blob : {"counter", "env_actions"}) EXPECT_EQ(x.at(blob), y.at(blob)) << blob;
  const json meta_x = json::parse(x.at("meta"));
  const json meta_y = json::parse(y.at("meta"));
  for (const char* member : {"env_digest", "recent_returns", "env_steps", "updates"}) {
    EXPECT_EQ(meta_x.at(member), meta_y.at(member)) << member;
  }
  const json config = json::parse(read_text(base / "stopped" / "config.json"));
  ASSERT_EQ(config.at("resumes").size(), 1U);
  EXPECT_EQ(config.at("resumes")[0].at("total_env_steps"), 192);
}

// A resume with its budget spent and summarized says so and changes nothing; a budget below the
// steps done and a setting that differs from the run's are refused; a time budget given to a
// resume allows one more update, and later resumes keep it.
TEST(TrainingRunTest, AResumeKeepsTheRunsBudgetAndRefusesWhatDoesNotFit) {
  const fs::path folder = test_folders::fresh_folder("training_run_budget") / "run";
  const CountingFactory factory;
  std::ostringstream out;
  std::ostringstream errors;
  ASSERT_TRUE(
      TrainingRun::create(factory, grid_settings(), folder, TrainBudget{16, 0.0}, {out, errors})
          .train()
          .has_value());
  const auto rows = [&] { return read_progress_csv(folder / "progress.csv").rows.size(); };
  ASSERT_EQ(rows(), 2U);

  std::ostringstream spent;
  EXPECT_FALSE(TrainingRun::resume(factory, folder, {}, {}, {spent, errors}).train());
  EXPECT_NE(spent.str().find("nothing to do, the run has spent its env steps (16 of 16): give "
                             "--steps N (more than 16) to train on"),
            std::string::npos)
      << spent.str();
  EXPECT_EQ(rows(), 2U);

  EXPECT_THROW(TrainingRun::resume(factory, folder, TrainBudget{16, 0.0}, {}, {out, errors}),
               RunRequestError);
  {
    // Another process training in the folder: a resume is refused before it reads anything.
    const RunLock other = RunLock::acquire(folder, "train");
    try {
      TrainingRun::resume(factory, folder, TrainBudget{24, 0.0}, {}, {out, errors});
      ADD_FAILURE() << "a resume of a folder in use was accepted";
    } catch (const std::runtime_error& error) {
      EXPECT_NE(std::string(error.what()).find("is in use: another process (pid"),
                std::string::npos)
          << error.what();
    }
    EXPECT_EQ(rows(), 2U);
  }
  ResumeChecks given;
  given.num_threads = 1;  // the run's
  given.eval_episodes = 3;
  try {
    TrainingRun::resume(factory, folder, TrainBudget{24, 0.0}, given, {out, errors});
    ADD_FAILURE() << "a differing --eval-episodes was accepted";
  } catch (const RunRequestError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("these differ from them: --eval-episodes 3 (the "
                        "run's: 2) (only --steps and --minutes may change)"),
              std::string::npos)
        << error.what();
  }

  // A picosecond more: spent before the first update, which given minutes allow all the same.
  ASSERT_TRUE(TrainingRun::resume(factory, folder, TrainBudget{400, 1e-14}, {}, {out, errors})
                  .train()
                  .has_value());
  EXPECT_EQ(rows(), 3U);
  std::ostringstream again;
  EXPECT_FALSE(TrainingRun::resume(factory, folder, {}, {}, {again, errors}).train());
  EXPECT_NE(again.str().find("nothing to do, the run has spent its time"), std::string::npos)
      << again.str();
  EXPECT_EQ(rows(), 3U);
}

}  // namespace
}  // namespace pixelgym::trainer
