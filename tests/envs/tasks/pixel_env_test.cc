// PixelEnv builds its renderer from the render resources it is given: at construction when it
// observes pixels, on the first render() when it observes state alone (no GL context until then);
// the msaa kwarg is checked against what that renderer's OpenGL offers.
#include "pixelgym/envs/tasks/pixel_env.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>

#include "pixelgym/envs/registry.h"
#include "pixelgym/render/context.h"

namespace pixelgym {
namespace {

TEST(PixelEnvRenderResourcesTest, APixelEnvBuildsItsRendererAtConstruction) {
  auto resources = std::make_shared<PixelRenderResources>(0, true);
  const std::unique_ptr<Env> env =
      make("CartPoleSwingup-v0", {{"width", 32}, {"height", 32}}, MakeOptions{resources});
  EXPECT_TRUE(resources->context_created());
}

TEST(PixelEnvRenderResourcesTest, AStateEnvCreatesNoContextUntilAskedToRender) {
  auto resources = std::make_shared<PixelRenderResources>(0, true);
  const std::unique_ptr<Env> env =
      make("CartPoleSwingup-v0", {{"obs_mode", "state"}}, MakeOptions{resources});
  env->reset(0);
  env->step(env->action_space().sample());
  EXPECT_FALSE(resources->context_created());
  const Array frame = env->render();
  EXPECT_TRUE(resources->context_created());
  EXPECT_EQ(frame.shape().size(), 3U);
}

// msaa takes 0 and the powers of two up to what the OpenGL offers (llvmpipe: 4; 8 on a GPU):
// make refuses more, naming the counts it takes, rather than the first reset failing.
TEST(PixelEnvMsaaTest, MsaaTakesWhatTheOpenGlOffersAndMakeRefusesMore) {
  const int most = render::Context().max_samples();
  std::string offered = "0";
  for (int samples = 2; samples <= std::min(most, 8); samples *= 2) {
    offered += ", " + std::to_string(samples);
  }
  for (const int samples : {0, 2, 4, 8}) {
    const Params kwargs = {
        {"width", 16}, {"height", 16}, {"obs_mode", "pixels"}, {"msaa", samples}};
    if (samples <= most) {
      const std::unique_ptr<Env> env = make("CartPoleSwingup-v0", kwargs);
      EXPECT_NO_THROW(env->reset(0)) << samples;
      continue;
    }
    try {
      make("CartPoleSwingup-v0", kwargs);
      ADD_FAILURE() << "msaa=" << samples << " was accepted where the OpenGL offers " << most;
    } catch (const std::invalid_argument& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find("CartPoleSwingup-v0: msaa=" + std::to_string(samples) +
                             " is more than this OpenGL offers ("),
                std::string::npos)
          << message;
      EXPECT_NE(message.find("): it takes msaa " + offered), std::string::npos) << message;
    }
  }
  // A state env renders no observation: its msaa is not checked against the OpenGL.
  EXPECT_NO_THROW(make("CartPoleSwingup-v0", {{"obs_mode", "state"}, {"msaa", 8}}));
}

}  // namespace
}  // namespace pixelgym
