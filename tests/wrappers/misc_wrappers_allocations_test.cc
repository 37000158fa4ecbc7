// The action, normalization, statistics and Dict wrappers: no allocation per step_into once
// warmed up (within an episode), and check_env passes on each over a real pixel env.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "pixelgym/envs/checker.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/wrappers/add_render_observation.h"
#include "pixelgym/wrappers/clip_action.h"
#include "pixelgym/wrappers/dtype_observation.h"
#include "pixelgym/wrappers/filter_observation.h"
#include "pixelgym/wrappers/normalize_observation.h"
#include "pixelgym/wrappers/normalize_reward.h"
#include "pixelgym/wrappers/record_episode_statistics.h"
#include "pixelgym/wrappers/rescale_action.h"
#include "tests/envs/step_allocation_counter.h"
#include "tests/wrappers/scripted_env.h"

namespace pixelgym::wrappers {
namespace {

// operator new calls in `steps` step_into calls after `warmup` uncounted ones; a step that ends
// an episode is not counted (RecordEpisodeStatistics allocates its info there, by design).
long count_step_news(Env& env, int warmup, int steps) {
  return testing::count_step_allocations(env, warmup, steps, testing::CountedSteps::kWithinEpisodes)
      .news_total();
}

void expect_no_allocations(Env& env, int warmup = 5, int steps = 40) {
  EXPECT_EQ(count_step_news(env, warmup, steps), 0) << env.name();
}

std::unique_ptr<Env> scripted() {
  auto env = std::make_unique<testing::ScriptedEnv>(testing::box(-1.0, 1.0, {2, 3}),
                                                    testing::box(-1.0, 1.0, {2}), 7);
  env->record = false;
  return env;
}

std::unique_ptr<Env> cartpole(const std::string& mode = "pixels+state") {
  return make("CartPoleSwingup-v0", {{"obs_mode", mode},
                                     {"width", 32},
                                     {"height", 32},
                                     {"render_width", 24},
                                     {"render_height", 20}});
}

// Every wrapper here, over `inner()`, keyed to "pixels" where it takes a key.
std::vector<std::unique_ptr<Env>> every_wrapper(
    const std::function<std::unique_ptr<Env>()>& inner) {
  std::vector<std::unique_ptr<Env>> envs;
  envs.push_back(std::make_unique<ClipAction>(inner()));
  envs.push_back(std::make_unique<RescaleAction>(inner(), -2.0, 2.0));
  envs.push_back(std::make_unique<NormalizeObservation>(inner(), "pixels"));
  envs.push_back(std::make_unique<NormalizeReward>(inner()));
  envs.push_back(std::make_unique<RecordEpisodeStatistics>(inner()));
  envs.push_back(std::make_unique<FilterObservation>(inner(), std::vector<std::string>{"pixels"}));
  envs.push_back(std::make_unique<DtypeObservation>(inner(), DType::kFloat32, "pixels"));
  return envs;
}

TEST(MiscWrapperAllocationsTest, TheCounterSeesNew) {
  const testing::AllocCounts counts =
      testing::count_allocations([] { auto vector = std::make_unique<std::vector<int>>(100); });
  EXPECT_GE(counts.news_total(), 2);
}

TEST(MiscWrapperAllocationsTest, OnABareBoxEnv) {
  expect_no_allocations(*std::make_unique<ClipAction>(scripted()));
  expect_no_allocations(*std::make_unique<RescaleAction>(scripted(), 0.0, 1.0));
  expect_no_allocations(*std::make_unique<NormalizeObservation>(scripted()));
  expect_no_allocations(*std::make_unique<NormalizeReward>(scripted()));
  expect_no_allocations(*std::make_unique<RecordEpisodeStatistics>(scripted()));
  expect_no_allocations(*std::make_unique<DtypeObservation>(scripted(), DType::kFloat64));
}

TEST(MiscWrapperAllocationsTest, OnARealPixelEnv) {
  for (const std::unique_ptr<Env>& env : every_wrapper([] { return cartpole(); })) {
    expect_no_allocations(*env, 10, 60);
  }
}

TEST(MiscWrapperAllocationsTest, AddRenderObservationAllocatesOnlyTheRenderedFrame) {
  AddRenderObservation env(cartpole("state"));
  // Each step renders one frame; render() returns it as a new Array (its shape, its memory and
  // the memory's control block), which the wrapper copies into the caller's buffer: the step
  // allocates what one render() call does, and nothing more.
  const int steps = 30;
  const long news = count_step_news(env, 5, steps);
  Array frame;
  const long render_news = testing::count_allocations([&] { frame = env.render(); }).news_total();
  std::printf("AddRenderObservation: %ld operator new calls in %d steps, %ld per render()\n", news,
              steps, render_news);
  EXPECT_GT(render_news, 0);
  EXPECT_LE(news, render_news * steps);
}

std::string failures(const CheckReport& report) {
  std::string text;
  for (const CheckResult& failure : report.failures()) {
    text += failure.name + ": " + failure.reason + "\n";
  }
  return text;
}

void expect_check_env_passes(Env& env) {
  const CheckReport report = check_env(env, CheckOptions{0, 30});
  EXPECT_TRUE(report.passed()) << env.name() << "\n" << failures(report);
}

TEST(MiscWrappersCheckEnvTest, EachWrapperOverARealEnvPasses) {
  for (const std::unique_ptr<Env>& env : every_wrapper([] { return cartpole(); })) {
    // Updating statistics makes a repeated seed give other observations and rewards, which
    // check_env's determinism checks refuse (as Gymnasium's would): check them frozen.
    if (auto* normalize = dynamic_cast<NormalizeObservation*>(env.get())) {
      normalize->set_update_statistics(false);
    }
    if (auto* normalize = dynamic_cast<NormalizeReward*>(env.get())) {
      normalize->set_update_statistics(false);
    }
    expect_check_env_passes(*env);
  }
  AddRenderObservation render(cartpole("state"));
  expect_check_env_passes(render);
  AddRenderObservation render_only(cartpole("pixels"), true);
  expect_check_env_passes(render_only);
}

TEST(MiscWrappersCheckEnvTest, NameOfAStack) {
  auto env = std::make_unique<NormalizeObservation>(cartpole(), "pixels");
  RecordEpisodeStatistics stack(std::make_unique<ClipAction>(std::move(env)));
  EXPECT_EQ(stack.name(),
            "RecordEpisodeStatistics<ClipAction<NormalizeObservation<TimeLimit<"
            "CartPoleSwingup-v0>>>>");
}

}  // namespace
}  // namespace pixelgym::wrappers
