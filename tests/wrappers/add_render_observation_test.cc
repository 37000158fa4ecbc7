// AddRenderObservation: the three layouts, the frame's space from metadata().render_shape before
// any reset, frame values equal to render(), errors.
#include "pixelgym/wrappers/add_render_observation.h"

#include <gtest/gtest.h>

#include <memory>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/spaces/discrete.h"
#include "tests/wrappers/scripted_env.h"
#include "tests/wrappers/test_util.h"

namespace pixelgym::wrappers {
namespace {

using testing::box;
using testing::ScriptedEnv;

std::unique_ptr<ScriptedEnv> scripted(SpacePtr space) {
  return std::make_unique<ScriptedEnv>(std::move(space), box(-1.0, 1.0, {1}));
}

SpacePtr dict_space() {
  return std::make_shared<spaces::Dict>(spaces::Dict::Entries{
      {"joints", box(-1.0, 1.0, {3})}, {"mode", std::make_shared<spaces::Discrete>(3)}});
}

const spaces::Box kFrame(0.0, 255.0, {6, 8, 3}, DType::kUInt8);

TEST(AddRenderObservationTest, BareObservationBecomesADict) {
  auto inner = scripted(box(-1.0, 1.0, {2}));
  ScriptedEnv* probe = inner.get();
  AddRenderObservation env(std::move(inner));
  const auto& dict = dynamic_cast<const spaces::Dict&>(env.observation_space());
  ASSERT_EQ(dict.entries().size(), 2U);
  EXPECT_EQ(dict.entries()[0].first, "state");
  EXPECT_EQ(dict.entries()[1].first, "pixels");
  EXPECT_TRUE(dict.at("state").equals(*box(-1.0, 1.0, {2})));
  EXPECT_TRUE(dict.at("pixels").equals(kFrame));
  const Value obs = testing::reset_and_step(env);
  EXPECT_TRUE(obs.dict().at("state").equals(probe->observations.back()));
  EXPECT_TRUE(obs.dict().at("pixels").array().equals(env.render()));
  EXPECT_EQ(obs.dict().at("pixels").array().data<std::uint8_t>()[0], 1);  // the step count
  EXPECT_EQ(probe->t, 1);
}

TEST(AddRenderObservationTest, DictObservationGetsTheFrameFirst) {
  auto inner = scripted(dict_space());
  ScriptedEnv* probe = inner.get();
  AddRenderObservation env(std::move(inner), false, "frame");
  const auto& dict = dynamic_cast<const spaces::Dict&>(env.observation_space());
  ASSERT_EQ(dict.entries().size(), 3U);
  EXPECT_EQ(dict.entries()[0].first, "frame");
  EXPECT_EQ(dict.entries()[1].first, "joints");
  EXPECT_EQ(dict.entries()[2].first, "mode");
  EXPECT_TRUE(dict.at("frame").equals(kFrame));
  ResetResult reset;
  reset.obs = env.observation_space().zeros();
  env.reset_into(reset, 0);
  EXPECT_TRUE(reset.obs.dict().at("joints").equals(probe->observations.back().dict().at("joints")));
  EXPECT_TRUE(reset.obs.dict().at("frame").array().equals(env.render()));
}

TEST(AddRenderObservationTest, RenderOnly) {
  AddRenderObservation env(scripted(box(-1.0, 1.0, {2})), true);
  EXPECT_TRUE(env.observation_space().equals(kFrame));
  const Value obs = testing::reset_and_step(env);
  EXPECT_TRUE(obs.array().equals(env.render()));
  EXPECT_TRUE(env.render_only());
}

TEST(AddRenderObservationTest, PixelTaskSpaceIsKnownBeforeAnyReset) {
  AddRenderObservation env(make(
      "PendulumSwingup-v0", {{"obs_mode", "state"}, {"render_width", 40}, {"render_height", 30}}));
  const auto& dict = dynamic_cast<const spaces::Dict&>(env.observation_space());
  EXPECT_TRUE(dict.at("pixels").equals(spaces::Box(0.0, 255.0, {30, 40, 3}, DType::kUInt8)));
  const Value obs = testing::reset_and_step(env);
  EXPECT_TRUE(env.observation_space().contains(obs));
  EXPECT_TRUE(obs.dict().at("pixels").array().equals(env.render()));
}

TEST(AddRenderObservationTest, Errors) {
  testing::expect_invalid(
      [] {
        auto inner = scripted(box(-1.0, 1.0, {2}));
        inner->meta.render_modes = {"human"};
        AddRenderObservation env(std::move(inner));
      },
      {"AddRenderObservation", "ScriptedEnv must render \"rgb_array\"", "[\"human\"]"});
  testing::expect_invalid(
      [] {
        auto inner = scripted(box(-1.0, 1.0, {2}));
        inner->meta.render_shape.reset();
        AddRenderObservation env(std::move(inner));
      },
      {"AddRenderObservation", "does not declare metadata().render_shape"});
  testing::expect_invalid(
      [] {
        auto inner = scripted(box(-1.0, 1.0, {2}));
        inner->meta.render_shape = Shape{6, 8, 4};
        AddRenderObservation env(std::move(inner));
      },
      {"AddRenderObservation", "(H, W, 3)", "(6, 8, 4)"});
  testing::expect_invalid(
      [] { AddRenderObservation env(scripted(dict_space()), false, "joints"); },
      {"AddRenderObservation", "\"joints\" is already a key", "keys: \"joints\", \"mode\""});
  testing::expect_invalid(
      [] { AddRenderObservation env(scripted(box(-1.0, 1.0, {2})), false, "x", "x"); },
      {"AddRenderObservation", "must differ", "\"x\""});
  testing::expect_invalid(
      [] { AddRenderObservation env(scripted(box(-1.0, 1.0, {2})), false, ""); },
      {"AddRenderObservation", "must not be empty"});
}

TEST(AddRenderObservationTest, AFrameOfAnotherShapeThanDeclaredIsARuntimeError) {
  auto inner = scripted(box(-1.0, 1.0, {2}));
  ScriptedEnv* probe = inner.get();
  AddRenderObservation env(std::move(inner));
  probe->meta.render_shape = Shape{5, 5, 3};  // the env now renders other frames
  EXPECT_THROW(env.reset(0), std::runtime_error);
}

}  // namespace
}  // namespace pixelgym::wrappers
