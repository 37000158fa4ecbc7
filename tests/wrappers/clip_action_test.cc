// ClipAction: the action space becomes Box(-inf, inf); actions are clipped into the inner bounds.
#include "pixelgym/wrappers/clip_action.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>

#include "pixelgym/envs/spaces/discrete.h"
#include "tests/wrappers/scripted_env.h"
#include "tests/wrappers/test_util.h"

namespace pixelgym::wrappers {
namespace {

using testing::box;
using testing::ScriptedEnv;

std::unique_ptr<ScriptedEnv> env_with_actions(SpacePtr actions) {
  return std::make_unique<ScriptedEnv>(box(-1.0, 1.0, {2}), std::move(actions));
}

TEST(ClipActionTest, SpaceIsUnboundedWithTheInnerShapeAndDtype) {
  const double inf = std::numeric_limits<double>::infinity();
  ClipAction f32(env_with_actions(std::make_shared<spaces::Box>(
      std::vector<double>{-1.0, 0.0, -2.0}, std::vector<double>{1.0, 0.5, 2.0}, Shape{3})));
  EXPECT_TRUE(f32.action_space().equals(spaces::Box(-inf, inf, {3}, DType::kFloat32)));
  ClipAction f64(env_with_actions(box(-1.0, 1.0, {2, 2}, DType::kFloat64)));
  EXPECT_TRUE(f64.action_space().equals(spaces::Box(-inf, inf, {2, 2}, DType::kFloat64)));
  EXPECT_TRUE(f64.observation_space().equals(*box(-1.0, 1.0, {2})));
  EXPECT_EQ(f64.name(), "ClipAction<ScriptedEnv>");
}

TEST(ClipActionTest, ClipsEachElementIntoItsBounds) {
  auto inner = env_with_actions(std::make_shared<spaces::Box>(
      std::vector<double>{-1.0, 0.0, -2.0}, std::vector<double>{1.0, 0.5, 2.0}, Shape{3}));
  ScriptedEnv* probe = inner.get();
  ClipAction env(std::move(inner));
  env.reset(0);
  const float inf = std::numeric_limits<float>::infinity();
  env.step(Array::from_vector<float>({3}, {-5.0F, 0.25F, inf}));
  env.step(Array::from_vector<float>({3}, {1.0F, 0.5F, -2.0F}));  // the edges stay
  env.step(Array::from_vector<float>({3}, {1.0001F, -0.0F, -inf}));
  ASSERT_EQ(probe->actions.size(), 3U);
  EXPECT_TRUE(probe->actions[0].equals(Array::from_vector<float>({3}, {-1.0F, 0.25F, 2.0F})));
  EXPECT_TRUE(probe->actions[1].equals(Array::from_vector<float>({3}, {1.0F, 0.5F, -2.0F})));
  EXPECT_TRUE(probe->actions[2].equals(Array::from_vector<float>({3}, {1.0F, -0.0F, -2.0F})));
}

TEST(ClipActionTest, Float64) {
  auto inner = env_with_actions(box(-0.5, 0.5, {2}, DType::kFloat64));
  ScriptedEnv* probe = inner.get();
  ClipAction env(std::move(inner));
  env.reset(0);
  env.step(Array::from_vector<double>({2}, {1e300, -0.25}));
  EXPECT_TRUE(probe->actions[0].equals(Array::from_vector<double>({2}, {0.5, -0.25})));
}

TEST(ClipActionTest, RefusesNonFloatBoxActionSpaces) {
  testing::expect_invalid(
      [] { ClipAction env(env_with_actions(std::make_shared<spaces::Discrete>(4))); },
      {"ClipAction", "float32 or float64 Box", "Discrete(4)"});
  testing::expect_invalid(
      [] { ClipAction env(env_with_actions(box(0.0, 5.0, {2}, DType::kInt32))); },
      {"ClipAction", "float32 or float64 Box", "int32"});
}

}  // namespace
}  // namespace pixelgym::wrappers
