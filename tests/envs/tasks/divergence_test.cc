// A simulation that diverges (an absurd force a task let through: 1e30, inf, NaN) ends the step
// with PhysicsDivergence naming the env and the step: never a non-finite observation or reward.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "pixelgym/envs/errors.h"
#include "pixelgym/envs/tasks/cartpole.h"
#include "pixelgym/envs/tasks/pixel_env.h"

namespace pixelgym {
namespace {

using ::testing::HasSubstr;

// The cart-pole swing-up whose cart and pole joints are handed `force` (N, N m) instead of the
// action's once `after` steps have run: what a wrapper or task that lets an absurd action through
// does (the World clamps a force to the motor's effort limit and refuses a non-finite one). A
// finite `force` above 1e100 is given as joint positions (m, rad) instead: a state beyond what a
// float32 observation holds.
class ForcedCartPole final : public Task {
 public:
  ForcedCartPole(double force, int after) : force_(force), after_(after) {}

  std::vector<std::string> camera_names() const override { return inner_.camera_names(); }
  SpacePtr action_space() const override { return inner_.action_space(); }
  std::vector<StateSpec> state_specs() const override { return inner_.state_specs(); }
  double control_timestep_s() const override { return inner_.control_timestep_s(); }
  engine::WorldConfig world_config() const override { return inner_.world_config(); }
  void build(engine::World& world) override { inner_.build(world); }
  render::Camera camera(const std::string& name, const engine::World& world) const override {
    return inner_.camera(name, world);
  }
  void initialize_episode(engine::World& world, Rng& rng) override {
    steps_ = 0;
    inner_.initialize_episode(world, rng);
  }
  void before_step(const Value& action, engine::World& world) override {
    inner_.before_step(action, world);
    if (steps_++ < after_) return;
    if (std::isfinite(force_) && std::abs(force_) > 1e100) {
      // Too large for any motor (and Bullet caps joint speeds): a position beyond float32 (the
      // cart's limit pulls it back within steps; the pole's angle stays).
      world.set_joint_state(engine::RobotId{0}, Eigen::Vector2d(force_, force_),
                            Eigen::Vector2d::Zero());
    } else {
      world.set_joint_commands(engine::RobotId{0}, Eigen::Vector2d(force_, force_));
    }
  }
  void observe(const engine::World& world, StateSlots& state) const override {
    inner_.observe(world, state);
    // The joint positions as the World has them (the cart-pole's own wraps and bounds them).
    Eigen::Vector2d positions;
    world.joint_positions(engine::RobotId{0}, positions);
    state.set("joint_pos", positions);
  }
  double reward(const engine::World& world) const override { return inner_.reward(world); }

 private:
  CartPoleTask inner_{true, false, 0};
  double force_;
  int after_;
  int steps_ = 0;
};

// Steps until the env throws (or 200 steps); returns the message, checking every observation and
// reward returned before it was finite.
std::string step_until_divergence(Env& env) {
  env.reset(0);
  const Value action = Array::from_vector<float>({1}, {0.5F});
  for (int step = 0; step < 200; ++step) {
    try {
      const StepResult result = env.step(action);
      EXPECT_TRUE(std::isfinite(result.reward)) << "step " << step;
      for (const Value& slot : result.obs.dict().values()) {
        const Array& array = slot.array();
        if (array.dtype() != DType::kFloat32) continue;
        for (std::int64_t i = 0; i < array.size(); ++i) {
          EXPECT_TRUE(std::isfinite(array.data<float>()[i])) << "step " << step;
        }
      }
    } catch (const PhysicsDivergence& error) {
      return error.what();
    }
  }
  return "";
}

class DivergenceTest : public ::testing::TestWithParam<double> {};

TEST_P(DivergenceTest, AnAbsurdForceEndsTheStepWithAnErrorNamingEnvAndStep) {
  TaskConfig config;
  config.obs_mode = "state";
  PixelEnv env(std::make_unique<ForcedCartPole>(GetParam(), 3), config, "ForcedCartPole");
  const std::string message = step_until_divergence(env);
  ASSERT_FALSE(message.empty()) << "force " << GetParam() << " never diverged";
  EXPECT_THAT(message, HasSubstr("ForcedCartPole: the simulation diverged at control step "));
  EXPECT_THAT(message, HasSubstr("reset() starts a new episode"));
  // The episode is over; a reset starts a new one that steps.
  EXPECT_THROW(env.step(Array::from_vector<float>({1}, {0.F})), ResetNeeded);
  env.reset(1);
}

INSTANTIATE_TEST_SUITE_P(Forces, DivergenceTest,
                         ::testing::Values(1e300, std::numeric_limits<double>::infinity(),
                                           std::numeric_limits<double>::quiet_NaN()),
                         [](const ::testing::TestParamInfo<double>& force) {
                           return std::isnan(force.param)   ? std::string("NaN")
                                  : std::isinf(force.param) ? std::string("Infinity")
                                                            : std::string("OneE300");
                         });

TEST(DivergenceTest, ALargeForceThatStaysFiniteStepsOn) {
  // 1e30 N m on the pole: the state grows but stays finite, and so does every observation.
  TaskConfig config;
  config.obs_mode = "state";
  PixelEnv env(std::make_unique<ForcedCartPole>(1e30, 3), config, "ForcedCartPole");
  const std::string message = step_until_divergence(env);
  if (!message.empty()) {
    EXPECT_THAT(message, HasSubstr("diverged at control step"));
  }
}

TEST(DivergenceTest, ANanForceIsCaughtAtTheStepItWasApplied) {
  TaskConfig config;
  config.obs_mode = "state";
  PixelEnv env(std::make_unique<ForcedCartPole>(std::numeric_limits<double>::quiet_NaN(), 3),
               config, "ForcedCartPole");
  EXPECT_THAT(step_until_divergence(env),
              HasSubstr("diverged at control step 4 of the episode: World::set_joint_commands: "
                        "non-finite command"));
}

}  // namespace
}  // namespace pixelgym
