// vector::NormalizeReward against a direct computation: the same scripted vector env stepped bare
// beside the wrapped one gives the raw rewards and flags; from them the test keeps each env's
// discounted return (reset after a done and by a reset; NextStep's reset step merges nothing) and
// the variance of every return merged, pooled with the prior, and expects every reward divided by
// its standard deviation. In each autoreset mode, for terminated and truncated episodes, in
// SyncVectorEnv and AsyncVectorEnv (2 threads). A batch of one env is the per-env wrapper bit for
// bit.
#include "pixelgym/wrappers/vector/normalize_reward.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "pixelgym/wrappers/normalize_reward.h"
#include "tests/envs/vector/vector_test_util.h"
#include "tests/wrappers/test_util.h"

namespace pixelgym::vector {
namespace {

using ::testing::ElementsAre;
using testing::scripted_actions;
using wrappers::RunningStatistics;

constexpr double kEpsilon = 1e-8;

// The variance of `samples` pooled with the prior (mean 0, var 1, count 1e-4).
double pooled_var(const std::vector<double>& samples) {
  const double count = RunningStatistics::kInitialCount + static_cast<double>(samples.size());
  double sum = 0.0;
  for (const double x : samples) sum += x;
  const double mean = sum / count;
  double squares = RunningStatistics::kInitialCount * (1.0 + mean * mean);
  for (const double x : samples) squares += (x - mean) * (x - mean);
  return squares / count;
}

bool done(const VectorStepResult& result, int i) {
  return result.terminated.data<bool>()[i] || result.truncated.data<bool>()[i];
}

class NormalizeRewardTest : public ::testing::TestWithParam<std::tuple<int, AutoresetMode, bool>> {
 protected:
  int threads() const { return std::get<0>(GetParam()); }
  AutoresetMode mode() const { return std::get<1>(GetParam()); }
  bool truncate() const { return std::get<2>(GetParam()); }
};

TEST_P(NormalizeRewardTest, RewardsAreScaledByTheVarianceOfTheReturnsMerged) {
  const std::vector<int> lengths{2, 3, 5};
  const double gamma = 0.9;
  const testing::ScriptedVector raw =
      testing::make_scripted_vector(lengths, truncate(), mode(), threads());
  NormalizeReward env(testing::make_scripted_vector(lengths, truncate(), mode(), threads()).env,
                      gamma);
  raw.env->reset(5);
  env.reset(5);
  std::vector<double> returns(3, 0.0);
  std::vector<bool> ended(3, false);
  std::vector<double> merged;
  for (int step = 1; step <= 20; ++step) {
    const std::string where =
        std::string(autoreset_mode_name(mode())) + " step " + std::to_string(step);
    const Value actions = scripted_actions(3, 0.1F);
    const VectorStepResult& bare = raw.env->step(actions);
    const VectorStepResult& result = env.step(actions);
    for (int i = 0; i < 3; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (mode() == AutoresetMode::kNextStep && ended[k]) {
        EXPECT_EQ(bare.rewards.data<double>()[i], 0.0) << where;
        continue;
      }
      returns[k] = gamma * returns[k] + bare.rewards.data<double>()[i];
      merged.push_back(returns[k]);
    }
    const double scale = std::sqrt(pooled_var(merged) + kEpsilon);
    EXPECT_NEAR(env.statistics().count,
                RunningStatistics::kInitialCount + static_cast<double>(merged.size()), 1e-9);
    EXPECT_NEAR(env.statistics().var[0], pooled_var(merged), 1e-9 * pooled_var(merged)) << where;
    for (int i = 0; i < 3; ++i) {
      const double want = bare.rewards.data<double>()[i] / scale;
      EXPECT_NEAR(result.rewards.data<double>()[i], want, 1e-9 * std::abs(want) + 1e-15)
          << where << ", env " << i;
      EXPECT_EQ(result.terminated.data<bool>()[i], bare.terminated.data<bool>()[i]) << where;
      EXPECT_EQ(result.truncated.data<bool>()[i], bare.truncated.data<bool>()[i]) << where;
    }
    std::vector<bool> masked(3, false);
    for (int i = 0; i < 3; ++i) {
      const auto k = static_cast<std::size_t>(i);
      ended[k] = done(bare, i);
      if (ended[k]) returns[k] = 0.0;
      masked[k] = ended[k];
      EXPECT_NEAR(env.discounted_returns()[k], returns[k], 1e-12) << where << ", env " << i;
    }
    if (mode() == AutoresetMode::kDisabled && (masked[0] || masked[1] || masked[2])) {
      // Reset the envs that ended, and env 2 too every fourth step (mid-episode): its return
      // restarts.
      if (step % 4 == 0) masked[2] = true;
      const Array mask = Array::from_vector<bool>({3}, {masked[0], masked[1], masked[2]});
      raw.env->reset(std::nullopt, {}, mask);
      env.reset(std::nullopt, {}, mask);
      for (std::size_t k = 0; k < 3; ++k) {
        if (masked[k]) returns[k] = 0.0;
      }
      EXPECT_EQ(env.discounted_returns(), returns) << where;
    }
  }
  EXPECT_GE(merged.size(), 40U);
}

// The rule by hand: lengths 2 and 3, gamma 0.5, rewards 0.5, 0.25, 0.125 by step, NextStep.
TEST(NormalizeRewardSingleTest, NextStepReturnsByHand) {
  NormalizeReward env(testing::make_scripted_vector({2, 3}, false, AutoresetMode::kNextStep).env,
                      0.5);
  env.reset(1);
  env.step(scripted_actions(2, 0.1F));  // both: R = 0.5 (2 merged)
  EXPECT_THAT(env.discounted_returns(), ElementsAre(0.5, 0.5));
  env.step(scripted_actions(2, 0.1F));  // env 0 ends with R = 0.5 (then 0); env 1: R = 0.5
  EXPECT_THAT(env.discounted_returns(), ElementsAre(0.0, 0.5));
  env.step(scripted_actions(2, 0.1F));  // env 0 resets (nothing merged); env 1 ends with 0.375
  EXPECT_THAT(env.discounted_returns(), ElementsAre(0.0, 0.0));
  env.step(scripted_actions(2, 0.1F));  // env 0: R = 0.5; env 1 resets (nothing merged)
  EXPECT_THAT(env.discounted_returns(), ElementsAre(0.5, 0.0));
  EXPECT_DOUBLE_EQ(env.statistics().count, RunningStatistics::kInitialCount + 6.0);
  EXPECT_NEAR(env.statistics().var[0], pooled_var({0.5, 0.5, 0.5, 0.5, 0.375, 0.5}), 1e-12);
}

TEST(NormalizeRewardSingleTest, OneEnvIsThePerEnvWrapperBitForBit) {
  // Truncated episodes of 3 steps, NextStep.
  NormalizeReward vector(testing::make_scripted_vector({3}, true, AutoresetMode::kNextStep).env);
  auto scripted = std::make_unique<testing::ScriptedEnv>(testing::box(-10.0, 10.0, {3}),
                                                         testing::box(-1.0, 1.0, {1}), 3, true);
  scripted->rewards = {0.5, 0.25, 0.125, 0.0625, 0.03125};
  wrappers::NormalizeReward single(std::move(scripted));
  vector.reset(2);
  single.reset(2);
  bool ended = false;
  for (int step = 0; step < 14; ++step) {
    const Value action = scripted_actions(1, 0.5F);
    const double got = vector.step(action).rewards.data<double>()[0];
    double want = 0.0;  // NextStep: the step after a done is the reset, reward 0
    if (ended) {
      single.reset();
      ended = false;
    } else {
      const StepResult stepped = single.step(action.array().index(0));
      want = stepped.reward;
      ended = stepped.truncated;
    }
    EXPECT_EQ(got, want) << "step " << step;
    EXPECT_EQ(vector.statistics().var, single.statistics().var) << "step " << step;
    EXPECT_EQ(vector.statistics().count, single.statistics().count) << "step " << step;
    EXPECT_EQ(vector.discounted_returns()[0], single.discounted_return()) << "step " << step;
  }
}

TEST(NormalizeRewardSingleTest, FreezingKeepsTheStatisticsAndRoundTrips) {
  NormalizeReward env(testing::make_scripted_vector({3, 4}, false, AutoresetMode::kSameStep).env);
  env.reset(1);
  env.step(scripted_actions(2, 0.1F));
  const RunningStatistics saved =
      RunningStatistics::from_value(env.statistics().to_value(), 1, "test");
  env.set_update_statistics(false);
  EXPECT_FALSE(env.update_statistics());
  const VectorStepResult& result = env.step(scripted_actions(2, 0.1F));
  EXPECT_EQ(env.statistics().var, saved.var);
  EXPECT_EQ(env.statistics().count, saved.count);
  EXPECT_DOUBLE_EQ(result.rewards.data<double>()[0], 0.25 / std::sqrt(saved.var[0] + kEpsilon));
  // The returns still accumulate while frozen.
  EXPECT_THAT(env.discounted_returns(), ElementsAre(0.99 * 0.5 + 0.25, 0.99 * 0.5 + 0.25));
  env.set_update_statistics(true);
  env.step(scripted_actions(2, 0.1F));
  EXPECT_NE(env.statistics().count, saved.count);
  env.set_statistics(saved);
  EXPECT_EQ(env.statistics().count, saved.count);
  RunningStatistics bad = saved;
  bad.count = 0.0;
  testing::expect_invalid([&] { env.set_statistics(bad); }, {"NormalizeReward", "count"});
  testing::expect_invalid([&] { env.set_statistics(RunningStatistics::initial(2)); },
                          {"NormalizeReward", "1 element"});
}

TEST(NormalizeRewardSingleTest, RefusesBadArguments) {
  const auto scripted = [] {
    return testing::make_scripted_vector({2}, false, AutoresetMode::kNextStep).env;
  };
  testing::expect_invalid([&] { NormalizeReward env(scripted(), 1.5); },
                          {"NormalizeReward", "gamma", "1.5"});
  testing::expect_invalid([&] { NormalizeReward env(scripted(), 0.9, -1.0); },
                          {"NormalizeReward", "epsilon", "-1"});
}

INSTANTIATE_TEST_SUITE_P(
    SyncAndPool, NormalizeRewardTest,
    ::testing::Combine(::testing::Values(0, 2),
                       ::testing::Values(AutoresetMode::kNextStep, AutoresetMode::kSameStep,
                                         AutoresetMode::kDisabled),
                       ::testing::Bool()),
    [](const ::testing::TestParamInfo<std::tuple<int, AutoresetMode, bool>>& param_info) {
      const int threads = std::get<0>(param_info.param);
      return (threads == 0 ? std::string("Sync") : "Threads" + std::to_string(threads)) +
             autoreset_mode_name(std::get<1>(param_info.param)) +
             (std::get<2>(param_info.param) ? "Truncated" : "Terminated");
    });

}  // namespace
}  // namespace pixelgym::vector
