// SteppedAlgorithm: the run's env loop around a StepLearner — iterations of the configured env
// steps, the stop check, the episodes' returns, and a resume that replays the envs and refills
// what the learner observed.
#include "pixelgym/trainer/stepped_algorithm.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/envs/tasks/grid_world.h"
#include "tests/examples/trainer/run/grid_envs.h"

namespace pixelgym::trainer {
namespace {

using test_envs::grid_envs;

class NoActor final : public Actor {
 public:
  ActCounts act(const Value&, bool, Value&) override { return {}; }
};

// Acts down or right in a pattern of the env steps done; keeps a sum of what it observed (the
// rewards and observations), as a replay buffer would; "updates" once every 3 env steps after
// the first 4 (a counter), asking stop after each.
class CountingLearner final : public StepLearner {
 public:
  void begin(const Value& first) override {
    ++begins;
    observed = observed * 31 + static_cast<std::uint64_t>(first.array().data<std::int64_t>()[0]);
  }
  void act(const Value&, std::int64_t env_steps, Value& actions) override {
    Array& batch = actions.array();
    for (std::int64_t i = 0; i < batch.shape()[0]; ++i) {
      batch.data<std::int64_t>()[i] =
          (env_steps / 2 + i) % 3 == 0 ? GridWorld::kRight : GridWorld::kDown;
    }
  }
  void observe(const Value& actions, const vector::VectorStepResult& step) override {
    ++observations;
    for (std::int64_t i = 0; i < step.rewards.shape()[0]; ++i) {
      // Unsigned: the sum wraps around (defined) instead of overflowing.
      observed = observed * 31 +
                 static_cast<std::uint64_t>(step.obs.array().data<std::int64_t>()[i]) +
                 static_cast<std::uint64_t>(actions.array().data<std::int64_t>()[i]) +
                 static_cast<std::uint64_t>(std::llround(step.rewards.data<double>()[i] * 100));
    }
  }
  bool learn(std::int64_t env_steps, const StopCheck& stop) override {
    if (env_steps <= 4 || env_steps % 3 != 0) return false;
    ++updates;
    return stop && stop(env_steps);
  }
  std::map<std::string, double> end_iteration(const LoopTimes& times) override {
    EXPECT_GE(times.env, 0.0);
    return {{"updates", static_cast<double>(updates)}};
  }
  std::vector<std::string> metric_names() const override { return {"updates"}; }
  void save(CheckpointBlobs&, nlohmann::json& meta) override { meta["updates"] = updates; }
  void restore(const LoadedCheckpoint&, const nlohmann::json& meta) override {
    updates = meta.at("updates").get<std::int64_t>();
  }
  Actor& actor() override { return actor_; }

  int begins = 0;
  std::int64_t observations = 0;
  std::uint64_t observed = 0;
  std::int64_t updates = 0;

 private:
  NoActor actor_;
};

struct Made {
  std::unique_ptr<vector::VectorEnv> envs;
  std::unique_ptr<EnvLoop> loop;  // the run's
  CountingLearner* learner;
  std::unique_ptr<SteppedAlgorithm> algorithm;
};

Made make(std::int64_t iteration_env_steps) {
  Made made;
  made.envs = grid_envs(2);
  auto learner = std::make_unique<CountingLearner>();
  made.learner = learner.get();
  made.loop = std::make_unique<EnvLoop>(*made.envs, 5, "test_episode");
  made.algorithm = std::make_unique<SteppedAlgorithm>(
      *made.loop, SteppedSettings{iteration_env_steps}, std::move(learner));
  return made;
}

TEST(SteppedAlgorithmTest, AnIterationTakesItsEnvStepsAndReportsTheLearnersMetrics) {
  Made made = make(40);
  double returns = 0.0;
  std::size_t episodes = 0;
  for (int k = 1; k <= 3; ++k) {
    const IterationStats stats = made.algorithm->iterate(nullptr);
    EXPECT_EQ(made.algorithm->env_steps(), 40 * k);
    EXPECT_EQ(made.algorithm->updates(), k);
    EXPECT_EQ(made.learner->observations, 20 * k);
    EXPECT_EQ(stats.metrics.at("updates"), static_cast<double>(made.learner->updates));
    returns += std::accumulate(stats.episode_returns.begin(), stats.episode_returns.end(), 0.0);
    episodes += stats.episode_returns.size();
  }
  EXPECT_EQ(made.learner->begins, 1);
  EXPECT_GT(episodes, 0u);  // GridWorld's episodes end within 50 steps
  EXPECT_NE(returns, 0.0);
  EXPECT_TRUE(made.loop->action_log_covers(made.algorithm->env_steps()));
  EXPECT_EQ(made.algorithm->metric_names(), std::vector<std::string>{"updates"});
}

TEST(SteppedAlgorithmTest, TheStopCheckEndsTheIterationAtTheStepItAnswers) {
  Made made = make(40);
  std::vector<std::int64_t> asked;
  made.algorithm->iterate([&asked](std::int64_t steps) {
    asked.push_back(steps);
    return steps >= 12;
  });
  EXPECT_EQ(made.algorithm->env_steps(), 12);
  EXPECT_EQ(made.algorithm->updates(), 1);
  EXPECT_EQ(made.learner->observations, 6);
  // Asked after every env step (2, 4, ...), once by the learner's update at 6 and 12.
  EXPECT_EQ(asked, (std::vector<std::int64_t>{2, 4, 6, 6, 8, 10, 12}));
}

TEST(SteppedAlgorithmTest, AResumeReplaysTheEnvsIntoTheLearnerAndGoesOnAsIfItHadNotStopped) {
  Made first = make(30);
  first.algorithm->iterate(nullptr);
  first.algorithm->iterate(nullptr);
  CheckpointBlobs blobs;
  nlohmann::json meta;
  first.algorithm->save(blobs, meta);

  Made resumed = make(30);
  resumed.algorithm->set_progress(first.algorithm->env_steps(), first.algorithm->updates());
  resumed.algorithm->restore(LoadedCheckpoint{}, meta);
  // As TrainingRun replays a checkpoint's actions through its loop.
  resumed.loop->replay(
      first.loop->action_log(), resumed.algorithm->env_steps(),
      [&](const Value& obs) { resumed.algorithm->replayed_reset(obs); },
      [&](const Value& actions, const vector::VectorStepResult& step) {
        resumed.algorithm->replayed_step(actions, step);
      });
  EXPECT_EQ(resumed.loop->digest(), first.loop->digest());
  EXPECT_EQ(resumed.learner->observed, first.learner->observed);
  EXPECT_EQ(resumed.learner->observations, first.learner->observations);

  first.algorithm->iterate(nullptr);
  resumed.algorithm->iterate(nullptr);
  EXPECT_EQ(resumed.loop->digest(), first.loop->digest());
  EXPECT_EQ(resumed.learner->observed, first.learner->observed);
  EXPECT_EQ(resumed.learner->updates, first.learner->updates);
  EXPECT_EQ(resumed.loop->action_log(), first.loop->action_log());
}

TEST(SteppedAlgorithmTest, RefusesAnIterationThatIsNotAMultipleOfTheEnvs) {
  auto envs = grid_envs(2);
  EnvLoop loop(*envs, 0, "e");
  EXPECT_THROW(SteppedAlgorithm(loop, SteppedSettings{3}, std::make_unique<CountingLearner>()),
               std::invalid_argument);
  EXPECT_THROW(SteppedAlgorithm(loop, SteppedSettings{0}, std::make_unique<CountingLearner>()),
               std::invalid_argument);
  EXPECT_THROW(SteppedAlgorithm(loop, SteppedSettings{4}, nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace pixelgym::trainer
