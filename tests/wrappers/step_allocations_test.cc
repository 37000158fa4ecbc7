// The image wrappers allocate nothing per step on the buffer path once warmed up.
//
// This binary replaces the global operator new and counts its calls while steps are measured
// (as tests/envs/step_allocations_test.cc does; the C allocator is not counted here: Mesa's
// llvmpipe mallocs while it draws, and that test attributes those).
//
// cv::resize builds its interpolation tables in scratch buffers (cv::AutoBuffer, operator new[]
// past about 1 KiB) on every call, for every size but an integer INTER_AREA shrink: 1 per call
// for INTER_AREA, 2 for INTER_LINEAR at the sizes below. OpenCV offers no way to hand it those
// buffers, so a `new` whose call stack has a frame in libopencv is counted apart as OpenCV's,
// printed, and bounded; pixelgym's own (every other) must be zero.
#include <dlfcn.h>
#include <execinfo.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <vector>

#include "envs/registry.h"
#include "tests/wrappers/image_env.h"
#include "wrappers/channel_first_observation.h"
#include "wrappers/grayscale_observation.h"
#include "wrappers/resize_observation.h"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_news{0};         // pixelgym's own: no frame in OpenCV
std::atomic<long> g_opencv_news{0};  // with a frame inside libopencv_*
thread_local bool t_in_hook = false;

void count_new() {
  if (!g_counting.load(std::memory_order_relaxed) || t_in_hook) return;
  t_in_hook = true;
  void* frames[64];
  const int depth = backtrace(frames, 64);
  bool opencv = false;
  for (int i = 0; i < depth && !opencv; ++i) {
    Dl_info info;
    if (dladdr(frames[i], &info) == 0 || info.dli_fname == nullptr) continue;
    opencv = std::strstr(info.dli_fname, "libopencv") != nullptr;
  }
  (opencv ? g_opencv_news : g_news).fetch_add(1);
  t_in_hook = false;
}

// backtrace() loads libgcc's unwinder (allocating) on its first call: do that before counting.
const bool g_unwinder_loaded = [] {
  void* frames[4];
  return backtrace(frames, 4) > 0;
}();
}  // namespace

void* operator new(std::size_t size) {
  count_new();
  if (void* pointer = std::malloc(size == 0 ? 1 : size)) return pointer;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
// The replaced operator new gets its memory from malloc, so free is the matching release; GCC
// cannot see that across the replacement and warns.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void operator delete(void* pointer) noexcept { std::free(pointer); }
void operator delete[](void* pointer) noexcept { std::free(pointer); }
void operator delete(void* pointer, std::size_t) noexcept { std::free(pointer); }
void operator delete[](void* pointer, std::size_t) noexcept { std::free(pointer); }
#pragma GCC diagnostic pop

namespace pixelgym::wrappers {
namespace {

struct News {
  long pixelgym = 0;  // must be 0
  long opencv = 0;    // inside cv::resize
};

// operator new calls during `steps` step_into calls after `warmup_steps` uncounted ones.
News count_step_news(Env& env, int warmup_steps, int steps) {
  ResetResult reset;
  reset.obs = env.observation_space().zeros();
  env.reset_into(reset, /*seed=*/0);
  StepResult step;
  step.obs = env.observation_space().zeros();
  Rng rng(1);
  std::vector<Value> actions;
  for (int i = 0; i < warmup_steps + steps; ++i) actions.push_back(env.action_space().sample(rng));
  News news;
  for (int i = 0; i < warmup_steps + steps; ++i) {
    g_news = 0;
    g_opencv_news = 0;
    g_counting = i >= warmup_steps;
    env.step_into(actions[static_cast<std::size_t>(i)], step);
    g_counting = false;
    news.pixelgym += g_news;
    news.opencv += g_opencv_news;
    if (step.terminated || step.truncated) env.reset_into(reset);  // not counted
  }
  return news;
}

std::unique_ptr<Env> dict_env() {
  return std::make_unique<testing::ImageEnv>(testing::pixels_and_state(64, 48, 3));
}

// Steps `env` and expects no allocation of pixelgym's and at most `opencv_per_step` inside
// OpenCV per step.
void expect_no_allocations(Env& env, long opencv_per_step, int warmup_steps = 5, int steps = 50) {
  const News news = count_step_news(env, warmup_steps, steps);
  EXPECT_EQ(news.pixelgym, 0) << env.name() << ": operator new calls in " << steps << " steps";
  EXPECT_LE(news.opencv, opencv_per_step * steps) << env.name();
  std::printf("%s: in %d steps, %ld operator new calls inside OpenCV\n", env.name().c_str(), steps,
              news.opencv);
}

TEST(ImageWrapperAllocationsTest, TheCounterSeesNew) {
  g_news = 0;
  g_counting = true;
  auto vector = std::make_unique<std::vector<int>>(100);
  g_counting = false;
  EXPECT_GE(g_news.load(), 2);
}

TEST(ImageWrapperAllocationsTest, DictFormsAllocateNothing) {
  GrayscaleObservation gray(dict_env(), true);
  expect_no_allocations(gray, 0);
  ChannelFirstObservation first(dict_env());
  expect_no_allocations(first, 0);
  ResizeObservation halve(dict_env(), {32, 24});  // integer INTER_AREA: OpenCV allocates nothing
  expect_no_allocations(halve, 0);
  ResizeObservation shrink(dict_env(), {40, 30});
  expect_no_allocations(shrink, 1);
  ResizeObservation grow(dict_env(), {100, 90});
  expect_no_allocations(grow, 2);
}

TEST(ImageWrapperAllocationsTest, WrappedRealEnvAllocatesNothing) {
  for (const char* mode : {"pixels", "pixels+state"}) {
    ChannelFirstObservation first(std::make_unique<GrayscaleObservation>(
        make("CartPoleSwingup-v0", {{"obs_mode", mode}}), true));
    expect_no_allocations(first, 0, 20, 100);
    ResizeObservation halve(make("CartPoleSwingup-v0", {{"obs_mode", mode}}), {42, 42});
    expect_no_allocations(halve, 0, 20, 100);
    auto shrink = std::make_unique<ResizeObservation>(
        make("CartPoleSwingup-v0", {{"obs_mode", mode}}), ImageSize{64, 64});
    auto gray = std::make_unique<GrayscaleObservation>(std::move(shrink));
    ResizeObservation grow(std::move(gray), {96, 96});
    expect_no_allocations(grow, 3, 20, 100);
  }
}

}  // namespace
}  // namespace pixelgym::wrappers
