// PixelEnv builds its renderer from the render resources it is given: at construction when it
// observes pixels, on the first render() when it observes state alone (no GL context until then).
#include "pixelgym/envs/tasks/pixel_env.h"

#include <gtest/gtest.h>

#include <memory>

#include "pixelgym/envs/registry.h"

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

}  // namespace
}  // namespace pixelgym
