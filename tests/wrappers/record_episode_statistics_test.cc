// RecordEpisodeStatistics: info["episode"] only at an episode's last step, for terminated and
// truncated episodes; return, length, time; the queues; errors.
#include "pixelgym/wrappers/record_episode_statistics.h"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "tests/wrappers/scripted_env.h"
#include "tests/wrappers/test_util.h"

namespace pixelgym::wrappers {
namespace {

using testing::box;
using testing::ScriptedEnv;

std::unique_ptr<ScriptedEnv> episodes_of(int length, bool truncate) {
  auto env =
      std::make_unique<ScriptedEnv>(box(-1.0, 1.0, {2}), box(-1.0, 1.0, {1}), length, truncate);
  env->rewards = {1.0, 0.5, -2.0};
  return env;
}

class RecordEpisodeStatisticsTest : public ::testing::TestWithParam<bool> {};

TEST_P(RecordEpisodeStatisticsTest, EpisodeInfoAtTheLastStepOnly) {
  RecordEpisodeStatistics env(episodes_of(4, GetParam()));
  env.reset(0);
  const Value action = env.action_space().zeros();
  for (int episode = 0; episode < 3; ++episode) {
    for (int t = 1; t <= 4; ++t) {
      const StepResult step = env.step(action);
      EXPECT_EQ(env.episode_length(), t);
      if (t < 4) {
        EXPECT_FALSE(step.info.contains("episode")) << "step " << t;
        continue;
      }
      EXPECT_EQ(step.terminated, !GetParam());
      EXPECT_EQ(step.truncated, GetParam());
      ASSERT_TRUE(step.info.contains("episode"));
      const ValueDict& stats = step.info.at("episode").dict();
      EXPECT_EQ(stats.keys(), (std::vector<std::string>{"r", "l", "t"}));
      // Rewards 1, 0.5, -2, 1.
      EXPECT_TRUE(stats.at("r").array().equals(Array::scalar<double>(0.5)));
      EXPECT_TRUE(stats.at("l").array().equals(Array::scalar<std::int64_t>(4)));
      EXPECT_EQ(stats.at("t").array().dtype(), DType::kFloat64);
      EXPECT_GT(stats.at("t").array().item<double>(), 0.0);
      EXPECT_EQ(env.episode_count(), episode + 1);
      env.reset();
      EXPECT_EQ(env.episode_return(), 0.0);
    }
  }
  EXPECT_EQ(env.return_queue(), (std::vector<double>{0.5, 0.5, 0.5}));
  EXPECT_EQ(env.length_queue(), (std::vector<std::int64_t>{4, 4, 4}));
  ASSERT_EQ(env.time_queue().size(), 3U);
  for (const double t : env.time_queue()) EXPECT_GT(t, 0.0);
}

INSTANTIATE_TEST_SUITE_P(EndBy, RecordEpisodeStatisticsTest, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& param) {
                           return param.param ? "Truncation" : "Termination";
                         });

TEST(RecordEpisodeStatisticsQueueTest, KeepsTheLastBufferLengthEpisodesOldestFirst) {
  auto inner = episodes_of(2, false);
  ScriptedEnv* probe = inner.get();
  RecordEpisodeStatistics env(std::move(inner), 3, "stats");
  const Value action = env.action_space().zeros();
  for (int episode = 0; episode < 5; ++episode) {
    probe->rewards = {static_cast<double>(episode)};  // episode k returns 2k
    env.reset(static_cast<std::uint64_t>(episode));
    EXPECT_FALSE(env.step(action).info.contains("stats"));
    EXPECT_TRUE(env.step(action).info.contains("stats"));
  }
  // A reset mid-episode does not count that episode.
  env.reset(0);
  env.step(action);
  env.reset(0);
  EXPECT_EQ(env.episode_count(), 5);
  EXPECT_EQ(env.return_queue(), (std::vector<double>{4.0, 6.0, 8.0}));
  EXPECT_EQ(env.length_queue(), (std::vector<std::int64_t>{2, 2, 2}));
  EXPECT_EQ(env.time_queue().size(), 3U);
}

TEST(RecordEpisodeStatisticsQueueTest, Errors) {
  testing::expect_invalid([] { RecordEpisodeStatistics env(episodes_of(2, false), 0); },
                          {"RecordEpisodeStatistics", "buffer_length must be >= 1, got 0"});
  testing::expect_invalid([] { RecordEpisodeStatistics env(episodes_of(2, false), 10, ""); },
                          {"RecordEpisodeStatistics", "stats_key must not be empty"});
  // Two recorders on the same key: the outer one finds the key taken.
  RecordEpisodeStatistics env(std::make_unique<RecordEpisodeStatistics>(episodes_of(1, false)));
  env.reset(0);
  try {
    env.step(env.action_space().zeros());
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), ::testing::HasSubstr("info already holds \"episode\""));
  }
}

}  // namespace
}  // namespace pixelgym::wrappers
