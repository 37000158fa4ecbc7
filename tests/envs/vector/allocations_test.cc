// A vector env step allocates nothing on the heap once warmed up — every registered env, bare and
// under resize + grayscale + frame_stack, in SyncVectorEnv and in AsyncVectorEnv (2 threads).
//
// tests/alloc_counter.h counts every allocation of the process (worker threads included) and
// attributes it by call stack. As in tests/envs/step_allocations_test.cc, Mesa's llvmpipe mallocs
// while it draws and Bullet when compound shapes start to touch, which no caller can avoid: those
// are printed, and every operator new and every malloc of pixelgym's own must be zero. Steps that
// autoreset an env (NextStep: the step after a done) are not counted: a reset is not the step
// path.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/vector/make_vec.h"
#include "pixelgym/wrappers/wrapper_spec.h"
#include "tests/alloc_counter.h"
#include "tests/envs/env_ids.h"

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

// Allocations during `steps` steps after `warmup` uncounted ones; `counted` gets the number of
// steps counted (those that autoreset no env).
AllocCounts count_step_allocations(VectorEnv& env, int warmup, int steps, int& counted) {
  Rng rng(1);
  std::vector<Value> actions;
  for (int t = 0; t < warmup + steps; ++t) actions.push_back(env.action_space().sample(rng));
  env.reset(0);
  AllocCounts counts;
  bool resets_next = false;
  counted = 0;
  for (int t = 0; t < warmup + steps; ++t) {
    const Value& action = actions[static_cast<std::size_t>(t)];
    if (t >= warmup && !resets_next) {
      const VectorStepResult* result = nullptr;
      counts += testing::count_allocations([&] { result = &env.step(action); });
      ++counted;
      resets_next = any_done(*result);
    } else {
      resets_next = any_done(env.step(action));
    }
  }
  return counts;
}

void expect_no_allocations(const std::string& id, const std::vector<std::string>& wrappers) {
  for (const int threads : {0, 2}) {
    const VectorOptions options{threads == 0 ? VectorMode::kSync : VectorMode::kAsync, threads,
                                AutoresetMode::kNextStep};
    const auto env = make_vec(id, 2, {}, pixelgym::wrappers::wrapping(wrappers), options);
    int counted = 0;
    const AllocCounts counts = count_step_allocations(*env, 20, 60, counted);
    EXPECT_GE(counted, 30) << id << ": too few steps counted";
    EXPECT_EQ(counts.news_total(), 0) << env->name() << ": operator new calls";
    EXPECT_EQ(counts.mallocs_of(AllocOwner::kPixelgym), 0) << env->name() << ": pixelgym's mallocs";
    std::printf("%s %s: in %d steps of 2 envs, %ld mallocs inside Mesa, %ld inside Bullet\n",
                env->name().c_str(), threads == 0 ? "sync" : "2 threads", counted,
                counts.mallocs_of(AllocOwner::kMesa), counts.mallocs_of(AllocOwner::kBullet));
  }
}

TEST(VectorAllocationsTest, TheCounterSeesAllocationsOnOtherThreads) {
  // Guards the test: allocations on a worker thread are counted too.
  const AllocCounts counts = testing::count_allocations([] {
    std::thread thread([] { const auto vector = std::make_unique<std::vector<int>>(100); });
    thread.join();
  });
  EXPECT_GE(counts.news_total(), 2);
}

class VectorAllocationsTest : public ::testing::TestWithParam<std::string> {};

TEST_P(VectorAllocationsTest, StepAllocatesNothingAfterWarmUp) {
  expect_no_allocations(GetParam(), {});
}

TEST_P(VectorAllocationsTest, WrappedStepAllocatesNothingAfterWarmUp) {
  const EnvDescription description = describe(GetParam());
  if (description.observation_space->to_string().find("uint8") == std::string::npos) {
    GTEST_SKIP() << GetParam() << " has no image observation";
  }
  expect_no_allocations(GetParam(), {"resize=64x64", "grayscale", "frame_stack=4"});
}

INSTANTIATE_TEST_SUITE_P(AllEnvs, VectorAllocationsTest, ::testing::ValuesIn(registered_ids()),
                         testing::env_id_test_name);

}  // namespace
}  // namespace pixelgym::vector
