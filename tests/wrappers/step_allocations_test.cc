// The image wrappers allocate nothing per step on the buffer path once warmed up.
//
// tests/alloc_counter.h counts every operator new and attributes it by call stack. A shrink by a
// non-integer factor goes through AreaResize (tables and buffers built once) and an integer one
// through cv::resize's INTER_AREA fast path: neither allocates. An enlargement goes through
// cv::resize's INTER_LINEAR, which builds its tables in scratch buffers (cv::AutoBuffer, operator
// new[] past about 1 KiB) on every call: 2 per call at the sizes below. OpenCV offers no way to
// hand it those buffers, so a `new` inside libopencv is counted apart, printed and bounded; every
// other `new` must be zero. (The C allocator is not asserted here:
// tests/envs/step_allocations_test.cc does that for the envs.)
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/wrappers/channel_first_observation.h"
#include "pixelgym/wrappers/grayscale_observation.h"
#include "pixelgym/wrappers/resize_observation.h"
#include "tests/envs/step_allocation_counter.h"
#include "tests/wrappers/image_env.h"

namespace pixelgym::wrappers {
namespace {

struct News {
  long pixelgym = 0;  // every operator new but OpenCV's: must be 0
  long opencv = 0;    // inside cv::resize
};

// operator new calls during `steps` step_into calls after `warmup_steps` uncounted ones.
News count_step_news(Env& env, int warmup_steps, int steps) {
  const testing::AllocCounts counts = testing::count_step_allocations(env, warmup_steps, steps);
  const long opencv = counts.news_of(testing::AllocOwner::kOpenCv);
  return {counts.news_total() - opencv, opencv};
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
  const testing::AllocCounts counts =
      testing::count_allocations([] { auto vector = std::make_unique<std::vector<int>>(100); });
  EXPECT_GE(counts.news_of(testing::AllocOwner::kPixelgym), 2);
}

TEST(ImageWrapperAllocationsTest, DictFormsAllocateNothing) {
  GrayscaleObservation gray(dict_env(), true);
  expect_no_allocations(gray, 0);
  ChannelFirstObservation first(dict_env());
  expect_no_allocations(first, 0);
  ResizeObservation halve(dict_env(), {32, 24});  // integer INTER_AREA: OpenCV allocates nothing
  expect_no_allocations(halve, 0);
  ResizeObservation shrink(dict_env(), {40, 30});  // non-integer: AreaResize
  expect_no_allocations(shrink, 0);
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
    expect_no_allocations(grow, 2, 20, 100);
  }
}

}  // namespace
}  // namespace pixelgym::wrappers
