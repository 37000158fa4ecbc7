// The image wrappers on real pixel envs: check_env passes, spaces and observations agree.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "pixelgym/envs/checker.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/wrappers/channel_first_observation.h"
#include "pixelgym/wrappers/grayscale_observation.h"
#include "pixelgym/wrappers/resize_observation.h"
#include "pixelgym/wrappers/wrapper_spec.h"

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

// On obs_mode "rgb" (a bare image Box) the wrapper specs give, byte for byte, what they give on
// the "pixels" key of obs_mode "pixels", and the wrapped env passes check_env.
TEST(ImageWrappersEnvTest, TheSameStackOnTheImageBoxAndOnThePixelsKey) {
  const std::vector<std::string> specs = {"resize=64x48", "grayscale", "frame_stack=3"};
  auto box = apply_wrappers(make("CartPoleSwingup-v1", {{"obs_mode", "rgb"}}), specs);
  auto dict = apply_wrappers(make("CartPoleSwingup-v1", {{"obs_mode", "pixels"}}), specs);
  EXPECT_TRUE(box->observation_space().equals(
      dynamic_cast<const spaces::Dict&>(dict->observation_space()).at("pixels")));
  EXPECT_EQ(box->observation_space().shape().value(), (Shape{3, 64, 48}));
  Rng actions(3);
  ASSERT_TRUE(box->reset(5).obs.array().equals(dict->reset(5).obs.dict().at("pixels").array()));
  for (int t = 0; t < 10; ++t) {
    const Value action = box->action_space().sample(actions);
    ASSERT_TRUE(
        box->step(action).obs.array().equals(dict->step(action).obs.dict().at("pixels").array()))
        << "step " << t;
  }
  expect_check_env_passes(*box);
}

}  // namespace
}  // namespace pixelgym::wrappers
