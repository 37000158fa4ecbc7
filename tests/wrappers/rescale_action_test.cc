// RescaleAction: [min, max] maps affinely onto the inner bounds, ends exactly, outside clipped.
#include "pixelgym/wrappers/rescale_action.h"

#include <gtest/gtest.h>

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

SpacePtr uneven() {
  return std::make_shared<spaces::Box>(std::vector<double>{0.0, -2.0, 10.0},
                                       std::vector<double>{1.0, 2.0, 20.0}, Shape{3});
}

TEST(RescaleActionTest, SpaceIsTheGivenRange) {
  RescaleAction env(env_with_actions(uneven()), -1.0, 1.0);
  EXPECT_TRUE(env.action_space().equals(spaces::Box(-1.0, 1.0, {3})));
  RescaleAction per_element(env_with_actions(uneven()), std::vector<double>{0.0, 0.0, -3.0},
                            std::vector<double>{1.0, 4.0, 3.0});
  EXPECT_TRUE(per_element.action_space().equals(
      spaces::Box(std::vector<double>{0.0, 0.0, -3.0}, std::vector<double>{1.0, 4.0, 3.0}, {3})));
  RescaleAction f64(env_with_actions(box(0.0, 2.0, {2}, DType::kFloat64)), -1.0, 1.0);
  EXPECT_TRUE(f64.action_space().equals(spaces::Box(-1.0, 1.0, {2}, DType::kFloat64)));
}

TEST(RescaleActionTest, MapsTheEdgesExactlyAndTheMiddleAffinely) {
  auto inner = env_with_actions(uneven());
  ScriptedEnv* probe = inner.get();
  RescaleAction env(std::move(inner), -1.0, 1.0);
  env.reset(0);
  env.step(Array::from_vector<float>({3}, {-1.0F, -1.0F, -1.0F}));
  env.step(Array::from_vector<float>({3}, {1.0F, 1.0F, 1.0F}));
  env.step(Array::from_vector<float>({3}, {0.0F, 0.5F, -0.5F}));
  ASSERT_EQ(probe->actions.size(), 3U);
  EXPECT_TRUE(probe->actions[0].equals(Array::from_vector<float>({3}, {0.0F, -2.0F, 10.0F})));
  EXPECT_TRUE(probe->actions[1].equals(Array::from_vector<float>({3}, {1.0F, 2.0F, 20.0F})));
  const float* middle = probe->actions[2].array().data<float>();
  EXPECT_FLOAT_EQ(middle[0], 0.5F);
  EXPECT_FLOAT_EQ(middle[1], 1.0F);
  EXPECT_FLOAT_EQ(middle[2], 12.5F);
}

TEST(RescaleActionTest, PerElementRangesAndFloat64) {
  auto inner = env_with_actions(box(-1.0, 1.0, {2}, DType::kFloat64));
  ScriptedEnv* probe = inner.get();
  RescaleAction env(std::move(inner), std::vector<double>{0.0, 10.0},
                    std::vector<double>{1.0, 30.0});
  env.reset(0);
  env.step(Array::from_vector<double>({2}, {0.25, 30.0}));
  const double* a = probe->actions[0].array().data<double>();
  EXPECT_DOUBLE_EQ(a[0], -0.5);
  EXPECT_DOUBLE_EQ(a[1], 1.0);
}

TEST(RescaleActionTest, StaysInsideTheInnerBoundsForRandomActions) {
  auto inner = env_with_actions(uneven());
  ScriptedEnv* probe = inner.get();
  RescaleAction env(std::move(inner), -3.0, 7.0);
  env.reset(0);
  Rng rng(5);
  for (int i = 0; i < 9; ++i) env.step(env.action_space().sample(rng));
  for (const Value& action : probe->actions) {
    EXPECT_TRUE(uneven()->contains(action)) << action.to_string();
  }
}

TEST(RescaleActionTest, RefusesBadSpacesAndRanges) {
  testing::expect_invalid(
      [] { RescaleAction env(env_with_actions(std::make_shared<spaces::Discrete>(3)), -1, 1); },
      {"RescaleAction", "float32 or float64 Box", "Discrete(3)"});
  const double inf = std::numeric_limits<double>::infinity();
  testing::expect_invalid([&] { RescaleAction env(env_with_actions(box(-inf, 1.0, {2})), -1, 1); },
                          {"RescaleAction", "finite bounds", "-inf"});
  testing::expect_invalid([] { RescaleAction env(env_with_actions(uneven()), 1.0, 1.0); },
                          {"RescaleAction", "min_action < max_action", "got min_action 1"});
  testing::expect_invalid([] { RescaleAction env(env_with_actions(uneven()), 2.0, -1.0); },
                          {"RescaleAction", "min_action 2 and max_action -1"});
  testing::expect_invalid([&] { RescaleAction env(env_with_actions(uneven()), -inf, 1.0); },
                          {"RescaleAction", "both finite", "-inf"});
  testing::expect_invalid(
      [] {
        RescaleAction env(env_with_actions(uneven()), std::vector<double>{0.0, 0.0},
                          std::vector<double>{1.0, 1.0});
      },
      {"RescaleAction", "min_action has 2 values, expected 1 or 3"});
  testing::expect_invalid([] { RescaleAction env(env_with_actions(uneven()), 1.0, 1.00000000001); },
                          {"RescaleAction", "equal once rounded to float32"});
}

}  // namespace
}  // namespace pixelgym::wrappers
