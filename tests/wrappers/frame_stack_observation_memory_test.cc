// FrameStackObservation's memory: what held observations keep alive, measured through the
// allocations they actually hold (each distinct Array::storage(), at the allocator's usable size),
// and the buffer path's allocations (tests/alloc_counter.h: include it in this one source only).
#include <gtest/gtest.h>
#include <malloc.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <set>
#include <unordered_set>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/wrappers/frame_stack_observation.h"
#include "tests/envs/step_allocation_counter.h"
#include "tests/wrappers/image_env.h"

namespace pixelgym::wrappers {
namespace {

constexpr std::int64_t kStack = 4;
constexpr std::size_t kFrameBytes = 84 * 84 * 3;

// Bytes of the distinct allocations that `observations` keep alive (one count per allocation,
// however many arrays view it), as the allocator sizes them.
std::size_t bytes_held(const std::vector<Value>& observations) {
  std::unordered_set<const void*> seen;
  std::size_t bytes = 0;
  for (const Value& obs : observations) {
    for (const Array& array : obs.leaves()) {
      const void* storage = array.storage().get();
      if (seen.insert(storage).second) bytes += malloc_usable_size(const_cast<void*>(storage));
    }
  }
  return bytes;
}

// One episode of 84x84x3 noise frames that outlasts every run here, stacked by 4 (kNewAxis).
std::unique_ptr<FrameStackObservation> make_stack(
    FrameStackLayout layout = FrameStackLayout::kNewAxis) {
  return std::make_unique<FrameStackObservation>(
      std::make_unique<testing::ImageEnv>(testing::image_box(84, 84, 3), 1'000'000), kStack,
      FrameStackPadding::kReset, "pixels", layout);
}

struct Held {
  std::vector<Value> observations;
  std::set<std::int64_t> frames;  // the distinct frames they show: 0 the reset's, t step t's
};

// Resets, steps `steps` times and keeps every `every`-th observation (the reset's included).
Held run(Env& env, int steps, int every) {
  Held held;
  const auto keep = [&](const Value& obs, std::int64_t t) {
    held.observations.push_back(obs);
    for (std::int64_t j = 0; j < kStack; ++j) held.frames.insert(std::max<std::int64_t>(0, t - j));
  };
  keep(env.reset(0).obs, 0);
  const Value action = env.action_space().zeros();
  for (int t = 1; t <= steps; ++t) {
    const StepResult step = env.step(action);
    if (t % every == 0) keep(step.obs, t);
  }
  return held;
}

double ratio(std::size_t bytes, const Held& held) {
  return static_cast<double>(bytes) / static_cast<double>(held.frames.size() * kFrameBytes);
}

TEST(FrameStackMemoryTest, AReplayBufferOfAThousandStepsHoldsEachFrameAboutOnce) {
  const auto env = make_stack();
  const Held held = run(*env, 1000, 1);
  ASSERT_EQ(held.frames.size(), 1001U);
  const std::size_t shared = bytes_held(held.observations);
  // Gymnasium 1.x copies the k frames into every observation: hold such copies, measured alike.
  std::vector<Value> copies;
  for (const Value& obs : held.observations) copies.push_back(obs.clone());
  const std::size_t copied = bytes_held(copies);
  std::printf(
      "1,000 steps, stack 4, 84x84x3, every observation held: %zu bytes in %lld tapes of %lld "
      "slots for 1001 distinct frames of %zu bytes = %.3fx (Gymnasium-style copies: %zu bytes = "
      "%.3fx)\n",
      shared, static_cast<long long>(env->tapes_allocated()),
      static_cast<long long>(env->tape_slots()), kFrameBytes, ratio(shared, held), copied,
      ratio(copied, held));
  EXPECT_LE(ratio(shared, held), 1.1);
  EXPECT_GE(ratio(copied, held), 3.9);
}

TEST(FrameStackMemoryTest, FiguresForTheTapeSize) {
  // The figures behind the tape size in frame_stack_observation.h (printed, not asserted).
  {
    const auto env = make_stack();
    const Held held = run(*env, 10'000, 1);
    std::printf("10,000 steps, every observation held: %.3fx\n",
                ratio(bytes_held(held.observations), held));
  }
  {
    const auto env = make_stack();
    const Held held = run(*env, 1000, 100);
    std::vector<Value> copies;
    for (const Value& obs : held.observations) copies.push_back(obs.clone());
    std::printf("1,000 steps, every 100th observation held: %.3fx (copies: %.3fx)\n",
                ratio(bytes_held(held.observations), held), ratio(bytes_held(copies), held));
  }
}

TEST(FrameStackMemoryTest, ACallerThatKeepsNothingUsesOneTape) {
  const auto env = make_stack();
  env->reset(0);
  const Value action = env->action_space().zeros();
  for (int t = 0; t < 1000; ++t) {
    env->step(action);  // the observation is dropped before the next step
  }
  EXPECT_EQ(env->tapes_allocated(), 1);
  // Keeping only the latest (assigned over, so that it is alive during the next step): the
  // tape it views cannot be rewound, the one before can: two tapes in turn.
  const auto latest = make_stack();
  StepResult step = latest->step((latest->reset(0), action));
  for (int t = 0; t < 1000; ++t) step = latest->step(action);
  std::printf("keeping nothing: %lld tape; keeping the latest: %lld tapes in 1,000 steps\n",
              static_cast<long long>(env->tapes_allocated()),
              static_cast<long long>(latest->tapes_allocated()));
  EXPECT_EQ(latest->tapes_allocated(), 2);
}

// operator new calls (all but OpenCV's) in `steps` step_into calls into a caller buffer after
// `warmup` uncounted ones; resets are not counted.
long count_step_news(Env& env, int warmup, int steps) {
  const testing::AllocCounts counts = testing::count_step_allocations(env, warmup, steps);
  return counts.news_total() - counts.news_of(testing::AllocOwner::kOpenCv);
}

TEST(FrameStackMemoryTest, StepIntoACallerBufferAllocatesNothing) {
  for (const FrameStackLayout layout :
       {FrameStackLayout::kNewAxis, FrameStackLayout::kChannelsFirst,
        FrameStackLayout::kChannelsLast}) {
    // Episodes of 10 steps: resets, and the tape rewound many times over 300 steps. A (C, H, W)
    // image, which every layout accepts.
    FrameStackObservation env(
        std::make_unique<testing::ImageEnv>(testing::pixels_and_state(3, 64, 48)), 4,
        FrameStackPadding::kZero, "pixels", layout);
    EXPECT_EQ(count_step_news(env, 5, 300), 0) << to_string(layout);
    EXPECT_EQ(env.tapes_allocated(), 1);
  }
  for (const char* mode : {"pixels", "pixels+state"}) {
    FrameStackObservation env(make("CartPoleSwingup-v0", {{"obs_mode", mode}}), 3);
    EXPECT_EQ(count_step_news(env, 20, 100), 0) << mode;
  }
}

}  // namespace
}  // namespace pixelgym::wrappers
