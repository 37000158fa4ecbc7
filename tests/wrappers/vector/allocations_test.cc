// The vector wrappers allocate nothing on a step once warmed up: RecordEpisodeStatistics,
// NormalizeReward and NormalizeObservation stacked over scripted envs (every autoreset mode) and
// over a pixel env with a frame stack (normalizing its "pixels"), in SyncVectorEnv and
// AsyncVectorEnv (2 threads).
//
// tests/alloc_counter.h counts every allocation of the process (worker threads included) by call
// stack, as tests/envs/vector/allocations_test.cc does. Steps that end an episode (they add
// infos) and NextStep's reset steps (a reset is not the step path) are not counted; a guard test
// shows that the counter sees the episode info a done step adds.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "pixelgym/envs/vector/make_vec.h"
#include "pixelgym/wrappers/vector/normalize_observation.h"
#include "pixelgym/wrappers/vector/normalize_reward.h"
#include "pixelgym/wrappers/vector/record_episode_statistics.h"
#include "pixelgym/wrappers/wrapper_spec.h"
#include "tests/alloc_counter.h"
#include "tests/envs/vector/vector_test_util.h"

namespace pixelgym::vector {
namespace {

using testing::AllocCounts;
using testing::AllocOwner;

bool any_done(const VectorStepResult& result) {
  for (int i = 0; i < result.rewards.size(); ++i) {
    if (result.terminated.data<bool>()[i] || result.truncated.data<bool>()[i]) return true;
  }
  return false;
}

// The three wrappers over `env`: statistics of raw rewards, inside the normalizations.
std::unique_ptr<VectorWrapper> wrap(std::unique_ptr<VectorEnv> env, const std::string& key) {
  auto statistics = std::make_unique<RecordEpisodeStatistics>(std::move(env));
  auto rewards = std::make_unique<NormalizeReward>(std::move(statistics));
  return std::make_unique<NormalizeObservation>(std::move(rewards), key);
}

// Scripted envs that record nothing and report no info (so that only the wrappers could
// allocate), episodes of `lengths`.
std::unique_ptr<VectorEnv> quiet_scripted(const std::vector<int>& lengths, AutoresetMode mode,
                                          int threads) {
  const EnvFactory factory = [&](int i) {
    auto env = std::make_unique<testing::ScriptedEnv>(testing::box(-10.0, 10.0, {3}),
                                                      testing::box(-1.0, 1.0, {1}),
                                                      lengths[static_cast<std::size_t>(i)]);
    env->record = false;
    env->offset = 2.0;
    return env;
  };
  return testing::make_vector_env(threads, static_cast<int>(lengths.size()), factory, mode);
}

// Allocations over `steps` steps after `warmup` uncounted ones; `counted` gets the number of
// steps counted: those that end no episode and (NextStep) follow no done. Disabled: the envs
// that ended are reset by mask (uncounted).
AllocCounts count_step_allocations(VectorWrapper& env, int warmup, int steps, int& counted) {
  const int n = env.num_envs();
  const Value actions = env.action_space().zeros();
  env.reset(0);
  AllocCounts counts;
  bool after_done = false;
  counted = 0;
  for (int t = 0; t < warmup + steps; ++t) {
    const VectorStepResult* result = nullptr;
    AllocCounts step_counts = testing::count_allocations([&] { result = &env.step(actions); });
    const bool done = any_done(*result);
    const bool reset_step = after_done && env.autoreset_mode() == AutoresetMode::kNextStep;
    if (t >= warmup && !done && !reset_step) {
      counts += step_counts;
      ++counted;
    }
    after_done = done;
    if (done && env.autoreset_mode() == AutoresetMode::kDisabled) {
      Array mask(DType::kBool, {n});
      for (int i = 0; i < n; ++i) {
        mask.data<bool>()[i] =
            result->terminated.data<bool>()[i] || result->truncated.data<bool>()[i];
      }
      env.reset(std::nullopt, {}, mask);
    }
  }
  return counts;
}

TEST(VectorWrapperAllocationsTest, TheCounterSeesTheInfoOfADoneStep) {
  const auto env = wrap(quiet_scripted({2, 9}, AutoresetMode::kNextStep, 0), "");
  env->reset(0);
  const Value actions = env->action_space().zeros();
  env->step(actions);
  const AllocCounts counts = testing::count_allocations([&] { env->step(actions); });
  EXPECT_GT(counts.news_total(), 0);
}

class VectorWrapperAllocationsTest
    : public ::testing::TestWithParam<std::tuple<int, AutoresetMode>> {};

TEST_P(VectorWrapperAllocationsTest, ScriptedStepsAllocateNothing) {
  const int threads = std::get<0>(GetParam());
  const AutoresetMode mode = std::get<1>(GetParam());
  const auto env = wrap(quiet_scripted({7, 9, 11}, mode, threads), "");
  int counted = 0;
  const AllocCounts counts = count_step_allocations(*env, 30, 60, counted);
  EXPECT_GE(counted, 30);
  EXPECT_EQ(counts.news_total(), 0) << env->name();
  EXPECT_EQ(counts.mallocs_total(), 0) << env->name();
}

TEST(VectorWrapperPixelAllocationsTest, PixelStepsAllocateNothing) {
  for (const int threads : {0, 2}) {
    const VectorOptions options{threads == 0 ? VectorMode::kSync : VectorMode::kAsync, threads,
                                AutoresetMode::kNextStep};
    const auto env = wrap(make_vec("CartPoleSwingup-v0", 2, {{"width", 32}, {"height", 32}},
                                   pixelgym::wrappers::wrapping({"frame_stack=2"}), options),
                          "pixels");
    int counted = 0;
    const AllocCounts counts = count_step_allocations(*env, 10, 30, counted);
    EXPECT_GE(counted, 20);
    EXPECT_EQ(counts.news_total(), 0) << env->name() << ": operator new calls";
    EXPECT_EQ(counts.mallocs_of(AllocOwner::kPixelgym), 0) << env->name() << ": pixelgym's";
    std::printf("%s %s: in %d steps of 2 envs, %ld mallocs inside Mesa, %ld inside Bullet\n",
                env->name().c_str(), threads == 0 ? "sync" : "2 threads", counted,
                counts.mallocs_of(AllocOwner::kMesa), counts.mallocs_of(AllocOwner::kBullet));
  }
}

INSTANTIATE_TEST_SUITE_P(
    SyncAndPool, VectorWrapperAllocationsTest,
    ::testing::Combine(::testing::Values(0, 2),
                       ::testing::Values(AutoresetMode::kNextStep, AutoresetMode::kSameStep,
                                         AutoresetMode::kDisabled)),
    [](const ::testing::TestParamInfo<std::tuple<int, AutoresetMode>>& param_info) {
      const int threads = std::get<0>(param_info.param);
      return (threads == 0 ? std::string("Sync") : "Threads" + std::to_string(threads)) +
             autoreset_mode_name(std::get<1>(param_info.param));
    });

}  // namespace
}  // namespace pixelgym::vector
