#include "pixelgym/envs/env.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "tests/envs/probe_env.h"

namespace pixelgym {
namespace {

using testing::action;
using ::testing::HasSubstr;
using testing::ProbeEnv;

TEST(EnvTest, StepBeforeResetThrowsResetNeeded) {
  ProbeEnv env;
  EXPECT_THROW(env.step(action(0.0F)), ResetNeeded);
  try {
    env.step(action(0.0F));
  } catch (const ResetNeeded& error) {
    EXPECT_THAT(error.what(), HasSubstr("ProbeEnv: step() called before reset()"));
  }
}

TEST(EnvTest, RenderBeforeResetThrows) {
  ProbeEnv env;
  EXPECT_THROW(env.render(), ResetNeeded);
}

TEST(EnvTest, StepAfterTerminatedNeedsReset) {
  ProbeEnv env(testing::Fault::kNone, /*episode_length=*/2);
  env.reset(0);
  EXPECT_FALSE(env.step(action(0.0F)).terminated);
  EXPECT_TRUE(env.step(action(0.0F)).terminated);
  try {
    env.step(action(0.0F));
    FAIL() << "expected ResetNeeded";
  } catch (const ResetNeeded& error) {
    EXPECT_THAT(error.what(), HasSubstr("after the episode ended"));
  }
  env.reset();
  EXPECT_NO_THROW(env.step(action(0.0F)));
  EXPECT_NO_THROW(env.render());  // rendering a finished episode is fine
}

TEST(EnvTest, ActionsOutsideTheSpaceAreRejectedNamingSpaceAndValue) {
  ProbeEnv env;
  env.reset(0);
  const std::vector<Value> bad = {
      Array::from_vector<double>({1}, {0.0}),        // wrong dtype
      Array::from_vector<float>({2}, {0.0F, 0.0F}),  // wrong shape
      Array::from_vector<float>({1}, {NAN}),         // NaN
      Array::from_vector<float>({1}, {1.5F}),        // out of bounds
      Value(ValueDict{{"a", Array::scalar(1.0F)}}),  // wrong structure
  };
  for (const Value& value : bad) {
    try {
      env.step(value);
      FAIL() << "accepted " << value.to_string();
    } catch (const std::invalid_argument& error) {
      EXPECT_THAT(error.what(), HasSubstr("ProbeEnv: step() action"));
      EXPECT_THAT(error.what(), HasSubstr("Box(-1.0, 1.0, (1,), float32)"));
      EXPECT_THAT(error.what(), HasSubstr(value.to_string()));
    }
  }
  // A rejected action does not end or advance the episode.
  EXPECT_EQ(env.t(), 0);
  EXPECT_NO_THROW(env.step(action(0.5F)));
}

TEST(EnvTest, ResetSeedReseedsAndUnseededResetContinues) {
  ProbeEnv env;
  const double first = (env.reset(10), env.x());
  const double continued = (env.reset(), env.x());
  const double again = (env.reset(10), env.x());
  const double continued_again = (env.reset(), env.x());
  EXPECT_EQ(first, again);
  EXPECT_EQ(continued, continued_again);
  EXPECT_NE(first, continued);
  EXPECT_NE(first, (env.reset(11), env.x()));
}

TEST(EnvTest, CloseIsIdempotentAndEndsUse) {
  ProbeEnv env;
  env.reset(0);
  env.close();
  env.close();
  EXPECT_EQ(env.close_calls(), 1);
  EXPECT_TRUE(env.closed());
  EXPECT_THROW(env.reset(0), ResetNeeded);
  EXPECT_THROW(env.step(action(0.0F)), ResetNeeded);
  EXPECT_THROW(env.render(), ResetNeeded);
}

TEST(EnvTest, UnregisteredEnvIsNamedByType) {
  ProbeEnv env;
  EXPECT_EQ(env.name(), "ProbeEnv");
  EXPECT_EQ(env.spec(), nullptr);
  EXPECT_EQ(&env.unwrapped(), &env);
}

}  // namespace
}  // namespace pixelgym
