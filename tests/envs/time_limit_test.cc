#include "pixelgym/envs/time_limit.h"

#include <gtest/gtest.h>

#include "tests/envs/probe_env.h"

namespace pixelgym {
namespace {

using testing::action;
using testing::ProbeEnv;

TEST(TimeLimitTest, TruncatesOnTheLimitStepAndResets) {
  TimeLimit env(std::make_unique<ProbeEnv>(testing::Fault::kNone, 100), 3);
  env.reset(0);
  EXPECT_FALSE(env.step(action(0.0F)).truncated);
  EXPECT_FALSE(env.step(action(0.0F)).truncated);
  const StepResult last = env.step(action(0.0F));
  EXPECT_TRUE(last.truncated);
  EXPECT_FALSE(last.terminated);
  EXPECT_EQ(env.elapsed_steps(), 3);
  EXPECT_THROW(env.step(action(0.0F)), ResetNeeded);
  env.reset();
  EXPECT_EQ(env.elapsed_steps(), 0);
  EXPECT_FALSE(env.step(action(0.0F)).truncated);
}

TEST(TimeLimitTest, TerminationBeforeTheLimitIsNotTruncation) {
  TimeLimit env(std::make_unique<ProbeEnv>(testing::Fault::kNone, 2), 5);
  env.reset(0);
  env.step(action(0.0F));
  const StepResult result = env.step(action(0.0F));
  EXPECT_TRUE(result.terminated);
  EXPECT_FALSE(result.truncated);
}

TEST(TimeLimitTest, RejectsNonPositiveLimit) {
  EXPECT_THROW(TimeLimit(std::make_unique<ProbeEnv>(), 0), std::invalid_argument);
}

}  // namespace
}  // namespace pixelgym
