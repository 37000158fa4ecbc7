// NormalizeReward: the discounted return's running variance against a direct computation, the
// scaled rewards, the return reset at both episode ends, freeze, checkpoint round trip, errors.
#include "pixelgym/wrappers/normalize_reward.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "tests/wrappers/scripted_env.h"
#include "tests/wrappers/test_util.h"

namespace pixelgym::wrappers {
namespace {

using testing::box;
using testing::ScriptedEnv;

std::unique_ptr<ScriptedEnv> reward_env(bool truncate) {
  auto env = std::make_unique<ScriptedEnv>(box(-1.0, 1.0, {2}), box(-1.0, 1.0, {1}), 5, truncate);
  env->rewards = {1.0, -2.0, 0.5, 3.0};
  return env;
}

struct Rollout {
  std::vector<double> rewards;  // as returned
  std::vector<bool> ends;       // the step ended the episode
};

Rollout run(Env& env, int steps) {
  Rollout result;
  env.reset(0);
  const Value action = env.action_space().zeros();
  for (int i = 0; i < steps; ++i) {
    const StepResult step = env.step(action);
    result.rewards.push_back(step.reward);
    result.ends.push_back(step.terminated || step.truncated);
    if (step.terminated || step.truncated) env.reset();
  }
  return result;
}

class NormalizeRewardTest : public ::testing::TestWithParam<bool> {};

TEST_P(NormalizeRewardTest, MatchesADirectComputation) {
  const double gamma = 0.9;
  NormalizeReward env(reward_env(GetParam()), gamma, 1e-8);
  const Rollout result = run(env, 23);
  // The raw rewards cycle through {1, -2, 0.5, 3} with the step count of the episode (5 steps).
  const std::vector<double> cycle = {1.0, -2.0, 0.5, 3.0};
  std::vector<double> returns;
  double r = 0.0;
  for (std::size_t i = 0; i < result.rewards.size(); ++i) {
    const double raw = cycle[(i % 5) % 4];
    r = gamma * r + raw;
    returns.push_back(r);
    // Each reward is scaled by the variance after this step's update: pooled with the prior
    // (mean 0, var 1, count 1e-4), computed from sums.
    const double prior = 1e-4;
    const double n = static_cast<double>(returns.size());
    double sum = 0.0;
    for (const double x : returns) sum += x;
    const double sample_mean = sum / n;
    double squares = 0.0;
    for (const double x : returns) squares += (x - sample_mean) * (x - sample_mean);
    const double var =
        (squares + prior + sample_mean * sample_mean * prior * n / (n + prior)) / (n + prior);
    EXPECT_NEAR(result.rewards[i], raw / std::sqrt(var + 1e-8), 1e-9) << "step " << i;
    if (i + 1 == result.rewards.size()) {
      EXPECT_NEAR(env.statistics().var[0], var, 1e-9);
      EXPECT_NEAR(env.statistics().mean[0], sum / (n + prior), 1e-9);
      EXPECT_NEAR(env.statistics().count, n + prior, 1e-9);
    }
    EXPECT_EQ(result.ends[i], (i + 1) % 5 == 0);
    if (result.ends[i]) r = 0.0;  // terminated or truncated alike
  }
  EXPECT_NEAR(env.discounted_return(), r, 1e-12);
}

INSTANTIATE_TEST_SUITE_P(EndBy, NormalizeRewardTest, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& param) {
                           return param.param ? "Truncation" : "Termination";
                         });

TEST(NormalizeRewardFreezeTest, ResetStartsANewReturn) {
  NormalizeReward env(reward_env(false), 0.5);
  env.reset(0);
  env.step(env.action_space().zeros());
  env.step(env.action_space().zeros());
  EXPECT_DOUBLE_EQ(env.discounted_return(), 0.5 * 1.0 - 2.0);
  env.reset();
  EXPECT_EQ(env.discounted_return(), 0.0);
}

TEST(NormalizeRewardFreezeTest, FrozenStatisticsStayAndStillScale) {
  NormalizeReward env(reward_env(false));
  run(env, 12);
  const RunningStatistics before = env.statistics();
  env.set_update_statistics(false);
  EXPECT_FALSE(env.update_statistics());
  const Rollout frozen = run(env, 4);  // a new episode: raw rewards 1, -2, 0.5, 3
  EXPECT_EQ(env.statistics().var, before.var);
  EXPECT_EQ(env.statistics().count, before.count);
  EXPECT_DOUBLE_EQ(frozen.rewards[1], -2.0 / std::sqrt(before.var[0] + 1e-8));
}

TEST(NormalizeRewardFreezeTest, StatisticsRoundTrip) {
  NormalizeReward env(reward_env(true));
  run(env, 9);
  NormalizeReward fresh(reward_env(true));
  fresh.set_statistics(RunningStatistics::from_value(env.statistics().to_value(), 1, "test"));
  EXPECT_EQ(fresh.statistics().mean, env.statistics().mean);
  EXPECT_EQ(fresh.statistics().var, env.statistics().var);
  EXPECT_EQ(fresh.statistics().count, env.statistics().count);
  env.set_update_statistics(false);
  fresh.set_update_statistics(false);
  EXPECT_EQ(run(fresh, 3).rewards, run(env, 3).rewards);
}

TEST(NormalizeRewardFreezeTest, Errors) {
  testing::expect_invalid([] { NormalizeReward env(reward_env(false), 1.5); },
                          {"NormalizeReward", "gamma must be in [0, 1], got 1.5"});
  testing::expect_invalid([] { NormalizeReward env(reward_env(false), std::nan("")); },
                          {"NormalizeReward", "gamma", "nan"});
  testing::expect_invalid([] { NormalizeReward env(reward_env(false), 0.99, -1.0); },
                          {"NormalizeReward", "epsilon must be finite and > 0, got -1"});
  NormalizeReward env(reward_env(false));
  testing::expect_invalid([&] { env.set_statistics(RunningStatistics::initial(2)); },
                          {"NormalizeReward", "1 element", "mean has 2 entries"});
}

}  // namespace
}  // namespace pixelgym::wrappers
