// make_vec owns what its envs share to render: one PixelRenderResources per thread that runs
// envs (copy w of Mesa for worker w), handed to each env of that thread; a single env made alone
// draws with a context of its own.
#include "envs/vector/make_vec.h"

#include <gtest/gtest.h>

#include <memory>
#include <set>

#include "envs/registry.h"
#include "envs/tasks/pixel_env.h"

namespace pixelgym::vector {
namespace {

const PixelRenderResources* resources_of(const VectorEnv& env, int i) {
  // Env::unwrapped() is not const; nothing is changed through it here.
  return dynamic_cast<const PixelEnv&>(const_cast<Env&>(env.env(i)).unwrapped()).render_resources();
}

TEST(MakeVecRenderResourcesTest, TheEnvsOfOneWorkerShareOneGroupOfItsMesaCopy) {
  const auto env = make_vec("CartPoleSwingup-v0", 5, {{"width", 32}, {"height", 32}}, nullptr,
                            {VectorMode::kAsync, 2});
  for (int i = 0; i < 5; ++i) {
    const PixelRenderResources* resources = resources_of(*env, i);
    ASSERT_NE(resources, nullptr) << "env " << i;
    EXPECT_EQ(resources, resources_of(*env, i % 2)) << "env " << i;
    EXPECT_EQ(resources->mesa_copy(), i % 2) << "env " << i;
    EXPECT_TRUE(resources->shares_context()) << "env " << i;
  }
  EXPECT_NE(resources_of(*env, 0), resources_of(*env, 1));
}

TEST(MakeVecRenderResourcesTest, SyncEnvsShareCopyZeroAndSharingCanBeTurnedOff) {
  const auto sync = make_vec("CartPoleSwingup-v0", 3, {{"width", 32}, {"height", 32}});
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(resources_of(*sync, i), resources_of(*sync, 0));
    EXPECT_EQ(resources_of(*sync, i)->mesa_copy(), 0);
  }
  VectorOptions options{VectorMode::kAsync, 2};
  options.share_gl_contexts = false;
  const auto apart =
      make_vec("CartPoleSwingup-v0", 2, {{"width", 32}, {"height", 32}}, nullptr, options);
  EXPECT_FALSE(resources_of(*apart, 0)->shares_context());
  EXPECT_EQ(resources_of(*apart, 1)->mesa_copy(), 1);
}

TEST(MakeVecRenderResourcesTest, AnEnvMadeAloneDrawsWithItsOwnContext) {
  const std::unique_ptr<Env> env = make("CartPoleSwingup-v0", {{"width", 32}, {"height", 32}});
  EXPECT_EQ(dynamic_cast<const PixelEnv&>(env->unwrapped()).render_resources(), nullptr);
  // Resources a pixel env cannot draw with are refused.
  class Other final : public RenderResources {};
  EXPECT_THROW(make("CartPoleSwingup-v0", {}, MakeOptions{std::make_shared<Other>()}),
               std::invalid_argument);
}

}  // namespace
}  // namespace pixelgym::vector
