// Registry::describe answers spaces, time limit and cameras without building a Bullet world or a
// GL context.
//
// How the test knows: this executable defines OSMesaCreateContextAttribs (how render::Context
// makes every GL context) and btAlignedAllocInternal (how Bullet allocates each of its objects,
// a dynamics world included); the dynamic linker binds the libraries' calls to these, which count
// and forward to the real functions. A control test makes and steps an env to show that the
// counters see both.
#include <GL/osmesa.h>
#include <dlfcn.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "tests/envs/env_ids.h"

namespace {

std::atomic<int> g_gl_contexts{0};
std::atomic<long> g_bullet_allocations{0};

template <typename Function>
Function next_symbol(const char* name) {
  void* symbol = dlsym(RTLD_NEXT, name);
  if (symbol == nullptr) std::abort();
  return reinterpret_cast<Function>(symbol);
}

}  // namespace

extern "C" OSMesaContext OSMesaCreateContextAttribs(const int* attributes, OSMesaContext shared) {
  using Create = OSMesaContext (*)(const int*, OSMesaContext);
  static const Create real = next_symbol<Create>("OSMesaCreateContextAttribs");
  ++g_gl_contexts;
  return real(attributes, shared);
}

// Bullet's allocator entry point (LinearMath/btAlignedAllocator.h), C++ linkage as Bullet has it.
void* btAlignedAllocInternal(std::size_t size, int alignment) {
  using Allocate = void* (*)(std::size_t, int);
  static const Allocate real = next_symbol<Allocate>("_Z22btAlignedAllocInternalmi");
  ++g_bullet_allocations;
  return real(size, alignment);
}

namespace pixelgym {
namespace {

using ::testing::HasSubstr;

class DescribeTest : public ::testing::TestWithParam<std::string> {};

TEST_P(DescribeTest, BuildsNoWorldAndNoGlContext) {
  const int contexts = g_gl_contexts;
  const long allocations = g_bullet_allocations;
  const EnvDescription description = describe(GetParam());
  EXPECT_EQ(g_gl_contexts, contexts);
  EXPECT_EQ(g_bullet_allocations, allocations);
  ASSERT_NE(description.observation_space, nullptr);
  ASSERT_NE(description.action_space, nullptr);
  EXPECT_GT(description.metadata.render_fps, 0.0);
}

TEST_P(DescribeTest, MatchesTheEnvMakeBuilds) {
  const EnvDescription description = describe(GetParam());
  std::unique_ptr<Env> env = make(GetParam());
  EXPECT_TRUE(description.observation_space->equals(env->observation_space()))
      << description.observation_space->to_string() << " vs "
      << env->observation_space().to_string();
  EXPECT_TRUE(description.action_space->equals(env->action_space()));
  EXPECT_EQ(description.metadata.render_fps, env->metadata().render_fps);
  ASSERT_NE(env->spec(), nullptr);
  EXPECT_EQ(description.max_episode_steps, env->spec()->max_episode_steps);
}

INSTANTIATE_TEST_SUITE_P(AllEnvs, DescribeTest, ::testing::ValuesIn(registered_ids()),
                         testing::env_id_test_name);

TEST(DescribeTest, TheCountersSeeAWorldAndAContext) {
  const int contexts = g_gl_contexts;
  const long allocations = g_bullet_allocations;
  // The counter sees OSMesa's contexts: this env draws with OSMesa whatever PIXELGYM_GL says.
  std::unique_ptr<Env> env = make("CartPoleSwingup-v0", {{"render_backend", "osmesa"}});
  env->reset(0);
  EXPECT_EQ(g_gl_contexts, contexts + 1);
  EXPECT_GT(g_bullet_allocations, allocations);
}

TEST(DescribeTest, FollowsKwargs) {
  const EnvDescription description =
      describe("CartPoleSwingup-v0", {{"width", 64}, {"height", 48}, {"action_repeat", 3}});
  const auto& space = dynamic_cast<const spaces::Dict&>(*description.observation_space);
  EXPECT_EQ(space.at("pixels").shape(), (Shape{48, 64, 3}));
  // 1000 control steps in env steps of 3: ceil(1000 / 3).
  EXPECT_EQ(description.max_episode_steps, 334);
  EXPECT_THAT(description.cameras, ::testing::ElementsAre("fixed", "tracking", "close"));
  EXPECT_DOUBLE_EQ(description.metadata.render_fps, 1.0 / 0.03);
  EXPECT_EQ(describe("CartPoleSwingup-v0", {{"max_episode_steps", 0}}).max_episode_steps,
            std::nullopt);
  EXPECT_EQ(describe("CartPoleSwingup-v0", {{"max_episode_steps", 77}}).max_episode_steps, 77);
  const auto state =
      describe("ArmReach-v0", {{"obs_mode", "state"}}).observation_space->to_string();
  EXPECT_THAT(state, ::testing::Not(HasSubstr("pixels")));
}

TEST(DescribeTest, RefusesWhatMakeRefuses) {
  EXPECT_THROW(describe("CartPoleSwingup-v9"), std::invalid_argument);
  EXPECT_THROW(describe("CartPoleSwingup-v0", {{"colour", 1}}), std::invalid_argument);
  EXPECT_THROW(describe("CartPoleSwingup-v0", {{"camera", "side"}}), std::invalid_argument);
}

// One truncation path: the spec's limit is the task's length, applied by TimeLimit, overridable.
int steps_until_truncated(Env& env, int cap) {
  env.reset(0);
  const Value action = env.action_space().sample();
  for (int t = 1; t <= cap; ++t) {
    const StepResult step = env.step(action);
    if (step.terminated) return -t;
    if (step.truncated) return t;
  }
  return 0;
}

TEST(TruncationTest, PixelTasksTruncateAtTheirLengthThroughTimeLimit) {
  std::unique_ptr<Env> env = make("CartPoleSwingup-v0", {{"obs_mode", "state"}});
  ASSERT_NE(env->spec(), nullptr);
  EXPECT_EQ(env->spec()->max_episode_steps, 1000);
  EXPECT_EQ(env->name(), "TimeLimit<CartPoleSwingup-v0>");
  EXPECT_EQ(steps_until_truncated(*env, 5000), 1000);
}

TEST(TruncationTest, MaxEpisodeStepsLengthensOrShortensAPixelTask) {
  std::unique_ptr<Env> longer =
      make("CartPoleSwingup-v0", {{"obs_mode", "state"}, {"max_episode_steps", 2000}});
  EXPECT_EQ(longer->spec()->max_episode_steps, 2000);
  EXPECT_EQ(steps_until_truncated(*longer, 5000), 2000);
  std::unique_ptr<Env> shorter = make("ArmReach-v0", {{"max_episode_steps", 7}});
  EXPECT_EQ(steps_until_truncated(*shorter, 5000), 7);
}

TEST(TruncationTest, ActionRepeatCountsEnvSteps) {
  std::unique_ptr<Env> env = make("ReacherEasy-v0", {{"obs_mode", "state"}, {"action_repeat", 4}});
  EXPECT_EQ(env->spec()->max_episode_steps, 250);
  EXPECT_EQ(steps_until_truncated(*env, 5000), 250);
}

TEST(TruncationTest, ZeroMeansNoLimitAndThePixelEnvItselfNeverTruncates) {
  std::unique_ptr<Env> env =
      make("PendulumSwingup-v0", {{"obs_mode", "state"}, {"max_episode_steps", 0}});
  EXPECT_EQ(env->spec()->max_episode_steps, std::nullopt);
  EXPECT_NE(dynamic_cast<PixelEnv*>(env.get()), nullptr);  // no TimeLimit around it
  EXPECT_EQ(steps_until_truncated(*env, 1500), 0);
}

}  // namespace
}  // namespace pixelgym
