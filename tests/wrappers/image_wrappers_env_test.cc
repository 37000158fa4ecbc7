// The image wrappers on real pixel envs: check_env passes, spaces and observations agree.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "pixelgym/envs/checker.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/wrappers/channel_first_observation.h"
#include "pixelgym/wrappers/grayscale_observation.h"
#include "pixelgym/wrappers/resize_observation.h"

namespace pixelgym::wrappers {
namespace {

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

TEST(ImageWrappersEnvTest, ResizeOnPixelsOnly) {
  ResizeObservation env(make("CartPoleSwingup-v0", {{"obs_mode", "pixels"}}), {32, 40});
  const auto& dict = dynamic_cast<const spaces::Dict&>(env.observation_space());
  EXPECT_EQ(dict.at("pixels").shape().value(), (Shape{32, 40, 3}));
  expect_check_env_passes(env);
}

TEST(ImageWrappersEnvTest, GrayscaleOnPixelsAndState) {
  GrayscaleObservation env(make("CartPoleSwingup-v0", {{"obs_mode", "pixels+state"}}), true);
  const auto& dict = dynamic_cast<const spaces::Dict&>(env.observation_space());
  EXPECT_EQ(dict.at("pixels").shape().value(), (Shape{84, 84, 1}));
  expect_check_env_passes(env);
}

TEST(ImageWrappersEnvTest, AStackOfAllThree) {
  auto env = std::make_unique<ResizeObservation>(
      make("CartPoleSwingup-v0", {{"obs_mode", "pixels+state"}}), ImageSize{64, 48});
  auto gray = std::make_unique<GrayscaleObservation>(std::move(env), true);
  ChannelFirstObservation stack(std::move(gray));
  const auto& dict = dynamic_cast<const spaces::Dict&>(stack.observation_space());
  EXPECT_EQ(dict.at("pixels").shape().value(), (Shape{1, 64, 48}));
  EXPECT_EQ(stack.name(),
            "ChannelFirstObservation<GrayscaleObservation<ResizeObservation<TimeLimit<"
            "CartPoleSwingup-v0>>>>");
  expect_check_env_passes(stack);
}

}  // namespace
}  // namespace pixelgym::wrappers
