#include "pixelgym/envs/tasks/grid_world.h"

#include <gtest/gtest.h>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/spaces/discrete.h"

namespace pixelgym {
namespace {

using Action = GridWorld::Action;

Value move(Action action) { return Array::scalar<std::int64_t>(action); }

std::int64_t cell_of(const Value& obs) { return obs.array().item<std::int64_t>(); }

TEST(GridWorldTest, SpacesAndStart) {
  GridWorld env;
  EXPECT_TRUE(env.observation_space().equals(spaces::Discrete(16)));
  EXPECT_TRUE(env.action_space().equals(spaces::Discrete(4)));
  EXPECT_EQ(cell_of(env.reset(0).obs), 0);
  EXPECT_EQ(cell_of(env.reset(12345).obs), 0);  // the start is fixed
}

TEST(GridWorldTest, ShortestPathEarnsStepPenaltiesThenGoalReward) {
  GridWorld env;
  env.reset(0);
  // Around the wall at (1, 1): right x3, down x3 reaches (3, 3) in six moves.
  const std::vector<Action> path = {GridWorld::kRight, GridWorld::kRight, GridWorld::kRight,
                                    GridWorld::kDown,  GridWorld::kDown,  GridWorld::kDown};
  const std::vector<std::int64_t> cells = {1, 2, 3, 7, 11, 15};
  double total = 0.0;
  for (std::size_t i = 0; i < path.size(); ++i) {
    const StepResult result = env.step(move(path[i]));
    EXPECT_EQ(cell_of(result.obs), cells[i]);
    EXPECT_FALSE(result.truncated);
    if (i + 1 < path.size()) {
      EXPECT_EQ(result.reward, -0.04);
      EXPECT_FALSE(result.terminated);
    } else {
      EXPECT_EQ(result.reward, 1.0);
      EXPECT_TRUE(result.terminated);
    }
    total += result.reward;
  }
  EXPECT_DOUBLE_EQ(total, 1.0 - 5 * 0.04);
  EXPECT_THROW(env.step(move(GridWorld::kLeft)), ResetNeeded);
}

TEST(GridWorldTest, WallAndBordersBlockWithoutEndingTheEpisode) {
  GridWorld env;
  env.reset(0);
  StepResult result = env.step(move(GridWorld::kUp));  // off the top
  EXPECT_EQ(cell_of(result.obs), 0);
  EXPECT_EQ(result.reward, -0.04);
  result = env.step(move(GridWorld::kLeft));  // off the left
  EXPECT_EQ(cell_of(result.obs), 0);
  env.step(move(GridWorld::kRight));          // (0, 1)
  result = env.step(move(GridWorld::kDown));  // into the wall at (1, 1)
  EXPECT_EQ(cell_of(result.obs), 1);
  EXPECT_FALSE(result.terminated);
  EXPECT_EQ(env.agent().row, 0);
}

TEST(GridWorldTest, RegisteredSpecTruncatesAtFiftySteps) {
  std::unique_ptr<Env> env = make("GridWorld-v0");
  env->reset(0);
  for (int t = 1; t <= 50; ++t) {
    const StepResult result = env->step(move(GridWorld::kUp));  // never reaches the goal
    EXPECT_EQ(result.reward, -0.04);
    EXPECT_FALSE(result.terminated);
    EXPECT_EQ(result.truncated, t == 50) << "step " << t;
  }
  EXPECT_THROW(env->step(move(GridWorld::kUp)), ResetNeeded);
}

TEST(GridWorldTest, ReachingTheGoalOnTheLastAllowedStepIsBothFlags) {
  std::unique_ptr<Env> env = make("GridWorld-v0", {{"max_episode_steps", 6}});
  env->reset(0);
  for (int i = 0; i < 3; ++i) env->step(move(GridWorld::kRight));
  for (int i = 0; i < 2; ++i) env->step(move(GridWorld::kDown));
  const StepResult result = env->step(move(GridWorld::kDown));
  EXPECT_TRUE(result.terminated);
  EXPECT_TRUE(result.truncated);
  EXPECT_EQ(result.reward, 1.0);
}

TEST(GridWorldTest, RejectsActionsOutsideDiscreteFour) {
  GridWorld env;
  env.reset(0);
  EXPECT_THROW(env.step(Array::scalar<std::int64_t>(4)), std::invalid_argument);
  EXPECT_THROW(env.step(Array::scalar<std::int64_t>(-1)), std::invalid_argument);
  EXPECT_THROW(env.step(Array::scalar<double>(1.0)), std::invalid_argument);
  EXPECT_THROW(env.reset(0, {{"unknown", 1}}), std::invalid_argument);
}

// Colour at the centre of cell (row, col) of a frame.
std::array<int, 3> cell_colour(const Array& frame, int row, int col) {
  const auto height = frame.shape()[0];
  const auto width = frame.shape()[1];
  const std::int64_t y = (2 * row + 1) * height / 8;
  const std::int64_t x = (2 * col + 1) * width / 8;
  const std::uint8_t* p = frame.data<std::uint8_t>() + (y * width + x) * 3;
  return {p[0], p[1], p[2]};
}

TEST(GridWorldTest, RenderDrawsAgentGoalWallAndFloor) {
  GridWorld env(GridWorldConfig{160, 120});
  env.reset(0);
  const Array frame = env.render();
  EXPECT_EQ(frame.shape(), (Shape{120, 160, 3}));
  EXPECT_EQ(cell_colour(frame, 0, 0), (std::array<int, 3>{31, 100, 200}));   // agent, blue
  EXPECT_EQ(cell_colour(frame, 3, 3), (std::array<int, 3>{46, 160, 67}));    // goal, green
  EXPECT_EQ(cell_colour(frame, 1, 1), (std::array<int, 3>{128, 128, 128}));  // wall, gray
  EXPECT_EQ(cell_colour(frame, 2, 0), (std::array<int, 3>{236, 236, 230}));  // floor
  env.step(move(GridWorld::kRight));
  const Array moved = env.render();
  EXPECT_EQ(cell_colour(moved, 0, 1), (std::array<int, 3>{31, 100, 200}));
  EXPECT_EQ(cell_colour(moved, 0, 0), (std::array<int, 3>{236, 236, 230}));
  EXPECT_FALSE(moved.shares_memory(frame));
}

TEST(GridWorldTest, PixelObservationsShowTheAgentMoving) {
  std::unique_ptr<Env> env = make("GridWorld-v0", {{"obs_mode", "pixels"}});
  const Value first = env->reset(0).obs;
  ASSERT_TRUE(env->observation_space().contains(first));
  const Array& frame = first.dict().at("pixels").array();
  EXPECT_EQ(frame.shape(), (Shape{84, 84, 3}));
  EXPECT_EQ(cell_colour(frame, 0, 0), (std::array<int, 3>{31, 100, 200}));
  const Value moved = env->step(move(GridWorld::kRight)).obs;
  EXPECT_EQ(cell_colour(moved.dict().at("pixels").array(), 0, 1),
            (std::array<int, 3>{31, 100, 200}));
  EXPECT_THROW(make("GridWorld-v0", {{"obs_mode", "rgba"}}), std::invalid_argument);
  // obs_mode "rgb": the same image as a bare Box.
  std::unique_ptr<Env> rgb = make("GridWorld-v0", {{"obs_mode", "rgb"}});
  const Value image = rgb->reset(0).obs;
  ASSERT_TRUE(image.is_array());
  EXPECT_TRUE(image.array().equals(frame));
  EXPECT_TRUE(
      rgb->step(move(GridWorld::kRight)).obs.array().equals(moved.dict().at("pixels").array()));
}

TEST(GridWorldTest, ConfigIsValidated) {
  EXPECT_THROW(make("GridWorld-v0", {{"render_width", 0}}), std::invalid_argument);
  EXPECT_THROW(make("GridWorld-v0", {{"render_height", 9000}}), std::invalid_argument);
  auto small = make("GridWorld-v0", {{"render_width", 64}, {"render_height", 32}});
  small->reset(0);
  EXPECT_EQ(small->render().shape(), (Shape{32, 64, 3}));
}

}  // namespace
}  // namespace pixelgym
