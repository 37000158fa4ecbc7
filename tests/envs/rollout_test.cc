#include "pixelgym/envs/rollout.h"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "pixelgym/envs/time_limit.h"
#include "tests/envs/probe_env.h"

namespace pixelgym {
namespace {

using testing::ProbeEnv;

float position(const Value& obs) { return obs.array().data<float>()[0]; }

// The loop RandomRollout stands for, written out: reset(seed), actions from Rng(seed), reset()
// when an episode ends. Returns the observation after each step (the reset's after an end).
std::vector<float> reference_positions(Env& env, std::uint64_t seed, int num_steps) {
  std::vector<float> positions;
  Rng action_rng(seed);
  env.reset(seed);
  for (int t = 0; t < num_steps; ++t) {
    StepResult step = env.step(env.action_space().sample(action_rng));
    if (step.terminated || step.truncated) step.obs = env.reset().obs;
    positions.push_back(position(step.obs));
  }
  return positions;
}

TEST(RandomRolloutTest, FollowsTheSeededLoopAcrossEpisodes) {
  ProbeEnv reference_env(testing::Fault::kNone, /*episode_length=*/4);
  const std::vector<float> expected = reference_positions(reference_env, 7, 11);

  ProbeEnv env(testing::Fault::kNone, /*episode_length=*/4);
  RandomRollout rollout(env, 7);
  for (int t = 0; t < 11; ++t) {
    rollout.step();
    EXPECT_EQ(position(rollout.observation()), expected[static_cast<std::size_t>(t)]) << t;
  }
  EXPECT_EQ(rollout.steps(), 11);
  EXPECT_EQ(rollout.episodes(), 2);  // ended at steps 4 and 8
}

TEST(RandomRolloutTest, DifferentSeedsGiveDifferentActions) {
  ProbeEnv a;
  ProbeEnv b;
  RandomRollout first(a, 1);
  RandomRollout second(b, 2);
  EXPECT_NE(position(first.observation()), position(second.observation()));
  const float start_a = position(first.observation());
  first.step();
  EXPECT_NE(position(first.observation()), start_a);
}

// The actions come from the rollout's own generator: reseeding the action space changes nothing.
TEST(RandomRolloutTest, IgnoresTheActionSpacesOwnGenerator) {
  ProbeEnv a;
  ProbeEnv b;
  a.action_space().seed(1);
  b.action_space().seed(2);
  RandomRollout first(a, 5);
  RandomRollout second(b, 5);
  for (int t = 0; t < 10; ++t) {
    first.step();
    second.step();
    EXPECT_EQ(position(first.observation()), position(second.observation())) << t;
  }
}

TEST(RandomRolloutTest, StepReturnsTheFinalObservationAndObservationTheReset) {
  ProbeEnv env(testing::Fault::kNone, /*episode_length=*/3);
  RandomRollout rollout(env, 3);
  rollout.step();
  rollout.step();
  EXPECT_FALSE(rollout.episode_ended());
  const StepResult& last = rollout.step();
  EXPECT_TRUE(last.terminated);
  EXPECT_TRUE(rollout.episode_ended());
  EXPECT_FLOAT_EQ(last.obs.array().data<float>()[1], 0.03F);              // t = 3
  EXPECT_FLOAT_EQ(rollout.observation().array().data<float>()[1], 0.0F);  // reset: t = 0
  EXPECT_EQ(env.t(), 0);
}

TEST(RandomRolloutTest, FinishEpisodeSumsTheRewardsOfOneEpisode) {
  ProbeEnv reference(testing::Fault::kNone, /*episode_length=*/5);
  Rng action_rng(9);
  reference.reset(9);
  double expected_return = 0.0;
  for (int t = 0; t < 5; ++t) {
    expected_return += reference.step(reference.action_space().sample(action_rng)).reward;
  }

  ProbeEnv env(testing::Fault::kNone, /*episode_length=*/5);
  RandomRollout rollout(env, 9);
  const EpisodeSummary first = rollout.finish_episode();
  EXPECT_EQ(first.length, 5);
  EXPECT_TRUE(first.terminated);
  EXPECT_DOUBLE_EQ(first.episode_return, expected_return);
  EXPECT_LT(first.episode_return, 0.0);
  const EpisodeSummary second = rollout.finish_episode();
  EXPECT_EQ(second.length, 5);
  EXPECT_NE(second.episode_return, first.episode_return);  // a fresh episode, not a sum of two
  EXPECT_EQ(rollout.episodes(), 2);
  EXPECT_EQ(rollout.steps(), 10);
}

TEST(RandomRolloutTest, TruncatedEpisodesAreNotTerminated) {
  TimeLimit env(std::make_unique<ProbeEnv>(testing::Fault::kNone, /*episode_length=*/100), 3);
  RandomRollout rollout(env, 0);
  const EpisodeSummary episode = rollout.finish_episode();
  EXPECT_EQ(episode.length, 3);
  EXPECT_FALSE(episode.terminated);
}

// Without the reset the env stays at the episode's end (render() shows its last frame), and the
// next step resets it first.
TEST(RandomRolloutTest, CanLeaveTheEnvAtTheEndOfAnEpisode) {
  ProbeEnv env(testing::Fault::kNone, /*episode_length=*/2);
  RandomRollout rollout(env, 4);
  rollout.finish_episode(/*reset_when_done=*/false);
  EXPECT_EQ(env.t(), 2);
  EXPECT_EQ(env.render().data<std::uint8_t>()[0], 2);
  EXPECT_THROW(env.step(testing::action(0.0F)), ResetNeeded);
  rollout.step();
  EXPECT_EQ(env.t(), 1);
  EXPECT_EQ(rollout.last_episode().length, 2);
  EXPECT_FALSE(rollout.episode_ended());
}

}  // namespace
}  // namespace pixelgym
