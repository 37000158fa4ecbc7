// The buffer path allocates nothing per step once warmed up, for every registered env.
//
// tests/alloc_counter.h counts every heap allocation (operator new and the C allocator) and
// attributes each by call stack to Mesa, Bullet or pixelgym. Mesa's llvmpipe mallocs while it
// draws (about 20-40 blocks per frame here); Bullet mallocs when a pair of compound collision
// shapes starts to overlap (its dispatcher creates a btCompoundCollisionAlgorithm, freed when the
// pair separates, so this never settles in a task whose contacts come and go). Neither can a
// caller avoid. pixelgym's own mallocs and every operator new must be zero; Mesa's and Bullet's
// counts are printed.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "tests/envs/env_ids.h"
#include "tests/envs/step_allocation_counter.h"

namespace pixelgym {
namespace {

using testing::AllocCounts;
using testing::AllocOwner;
using testing::count_allocations;
using testing::count_step_allocations;

TEST(StepAllocationsTest, TheCounterSeesAllocations) {
  // Guards the test itself: a counter that sees nothing would make every test below pass.
  const AllocCounts counts = count_allocations([] {
    const auto vector = std::make_unique<std::vector<int>>(100);
    void* raw = std::malloc(64);
    std::free(raw);
  });
  EXPECT_GE(counts.news_total(), 2);                       // the vector object and its elements
  EXPECT_GE(counts.mallocs_of(AllocOwner::kPixelgym), 3);  // those two, and the malloc
  EXPECT_EQ(counts.mallocs_of(AllocOwner::kMesa), 0);
  EXPECT_EQ(counts.mallocs_of(AllocOwner::kBullet), 0);
}

class StepAllocationsTest : public ::testing::TestWithParam<std::string> {};

TEST_P(StepAllocationsTest, StepIntoAllocatesNothingAfterWarmUp) {
  std::unique_ptr<Env> env = make(GetParam());
  const AllocCounts counts = count_step_allocations(*env, /*warmup_steps=*/20, /*steps=*/100);
  EXPECT_EQ(counts.news_total(), 0) << GetParam() << ": operator new calls in 100 steps";
  EXPECT_EQ(counts.mallocs_of(AllocOwner::kPixelgym), 0)
      << GetParam() << ": pixelgym's malloc calls in 100 steps";
  std::printf("%s: in 100 steps, %ld mallocs inside Mesa, %ld inside Bullet\n", GetParam().c_str(),
              counts.mallocs_of(AllocOwner::kMesa), counts.mallocs_of(AllocOwner::kBullet));
}

TEST_P(StepAllocationsTest, StateModeAllocatesNothingOutsideBullet) {
  // No GL at all in state mode, so not even Mesa allocates.
  if (GetParam() == "GridWorld-v0") GTEST_SKIP() << "GridWorld has no state mode";
  std::unique_ptr<Env> env = make(GetParam(), {{"obs_mode", "state"}});
  const AllocCounts counts = count_step_allocations(*env, 20, 100);
  EXPECT_EQ(counts.news_total(), 0) << GetParam();
  EXPECT_EQ(counts.mallocs_of(AllocOwner::kPixelgym) + counts.mallocs_of(AllocOwner::kMesa), 0)
      << GetParam();
  std::printf("%s, obs_mode=state: in 100 steps, %ld mallocs inside Bullet\n", GetParam().c_str(),
              counts.mallocs_of(AllocOwner::kBullet));
}

TEST_P(StepAllocationsTest, StepIntoWritesIntoTheCallersBuffer) {
  std::unique_ptr<Env> env = make(GetParam());
  ResetResult reset;
  reset.obs = env->observation_space().zeros();
  const std::vector<Array> reset_leaves = reset.obs.leaves();
  env->reset_into(reset, 0);
  // The observation is in the caller's arrays (no array of the env's own swapped in) and equals
  // what reset() gives for the same seed.
  const std::vector<Array> after = reset.obs.leaves();
  ASSERT_EQ(after.size(), reset_leaves.size());
  for (std::size_t i = 0; i < after.size(); ++i) {
    EXPECT_EQ(after[i].raw_data(), reset_leaves[i].raw_data()) << "leaf " << i;
  }
  std::unique_ptr<Env> other = make(GetParam());
  EXPECT_TRUE(other->reset(0).obs.equals(reset.obs));
}

TEST_P(StepAllocationsTest, StepIntoRefusesABufferOfAnotherLayout) {
  std::unique_ptr<Env> env = make(GetParam());
  env->reset(0);
  StepResult step;  // obs: an empty float32 array
  EXPECT_THROW(env->step_into(env->action_space().sample(), step), std::invalid_argument);
}

INSTANTIATE_TEST_SUITE_P(AllEnvs, StepAllocationsTest, ::testing::ValuesIn(registered_ids()),
                         testing::env_id_test_name);

TEST(StepAllocationsTest, GridWorldPixelsAllocatesNothing) {
  std::unique_ptr<Env> env = make("GridWorld-v0", {{"obs_mode", "pixels"}});
  const AllocCounts counts = count_step_allocations(*env, 20, 100);
  EXPECT_EQ(counts.news_total(), 0);
  EXPECT_EQ(counts.mallocs_total(), 0);
}

}  // namespace
}  // namespace pixelgym
