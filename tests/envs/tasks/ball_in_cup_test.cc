#include "pixelgym/envs/tasks/ball_in_cup.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <memory>
#include <numeric>
#include <vector>

#include "pixelgym/engine/world.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/rng.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "tests/envs/tasks/scripted.h"

namespace pixelgym {
namespace {

using testing::state;

PixelEnv& pixel_env(Env& env) { return dynamic_cast<PixelEnv&>(env.unwrapped()); }
const BallInCupTask& task_of(Env& env) {
  return dynamic_cast<const BallInCupTask&>(pixel_env(env).task());
}
const engine::World& world_of(Env& env) { return pixel_env(env).world(); }

Value action(double x, double z) {
  return Array::from_vector<float>({2}, {static_cast<float>(std::clamp(x, -1.0, 1.0)),
                                         static_cast<float>(std::clamp(z, -1.0, 1.0))});
}

// A catch planned on the model: the cross-entropy method over open-loop plans of 60 knots, each
// holding an action for 5 control steps (300 steps, 6 s), scored by the reward of the episode's
// start played out on a second copy of the env (reset with the same seed: the same start, the
// same physics). A plan is played until the ball is first in the cup; then the cup is left
// alone (no force) and the ball rests in it.
constexpr int kKnotSteps = 5;
constexpr int kKnots = 60;
using Plan = std::vector<std::array<double, 2>>;

// Plays `plan` (then no force once the ball is in) for `steps` from seed's start; the return.
double play(Env& env, std::uint64_t seed, const Plan& plan, int steps) {
  env.reset(seed);
  double total = 0.0;
  bool caught = false;
  for (int t = 0; t < steps; ++t) {
    const std::size_t knot = static_cast<std::size_t>(t / kKnotSteps);
    const StepResult step = env.step(
        caught || knot >= plan.size() ? action(0, 0) : action(plan[knot][0], plan[knot][1]));
    total += step.reward;
    caught = caught || step.reward > 0;
    if (step.terminated || step.truncated) break;
  }
  return total;
}

Plan plan_catch(std::uint64_t seed) {
  std::unique_ptr<Env> model = make("BallInCupCatch-v0", {{"obs_mode", "state"}});
  Rng rng(seed);
  Plan mean(kKnots, {0.0, 0.0});
  std::vector<std::array<double, 2>> spread(kKnots, {0.8, 0.8});
  Plan best;
  double best_score = -1.0;
  constexpr int kPopulation = 24;
  constexpr int kElite = 6;
  for (int iteration = 0; iteration < 16 && best_score < 250.0; ++iteration) {
    std::vector<Plan> population(kPopulation, mean);
    std::vector<double> scores(kPopulation);
    for (int i = 0; i < kPopulation; ++i) {
      if (i > 0) {  // the first keeps the mean
        for (int k = 0; k < kKnots; ++k) {
          for (int j = 0; j < 2; ++j) {
            population[i][k][j] = mean[k][j] + spread[k][j] * rng.normal();
          }
        }
      }
      scores[i] = play(*model, seed, population[i], kKnots * kKnotSteps);
      if (scores[i] > best_score) {
        best_score = scores[i];
        best = population[i];
      }
    }
    std::vector<int> order(kPopulation);
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int a, int b) { return scores[a] > scores[b]; });
    for (int k = 0; k < kKnots; ++k) {
      for (int j = 0; j < 2; ++j) {
        double sum = 0.0;
        double square = 0.0;
        for (int e = 0; e < kElite; ++e) {
          const double v = population[order[e]][k][j];
          sum += v;
          square += v * v;
        }
        mean[k][j] = sum / kElite;
        spread[k][j] = std::sqrt(std::max(0.0, square / kElite - mean[k][j] * mean[k][j])) + 0.05;
      }
    }
  }
  return best;
}

TEST(BallInCupTest, APlannedCatchScoresNearTheTopFarAboveRandomActions) {
  std::unique_ptr<Env> env = make("BallInCupCatch-v0", {{"obs_mode", "state"}});
  double planned = 0.0;
  double random = 0.0;
  for (std::uint64_t seed = 2; seed < 5; ++seed) {
    planned += play(*env, seed, plan_catch(seed), 1000) / 3.0;
    random += testing::episode_return(*env, seed, testing::random_policy(*env, seed)) / 3.0;
  }
  std::cout << "BallInCupCatch-v0 mean return over seeds 2-4: planned catch " << planned
            << ", random " << random << "\n";
  EXPECT_GE(planned, 850.0);  // the ball is in the cup within 3 s and stays there
  EXPECT_LE(random, 50.0);
}

TEST(BallInCupTest, TheRewardIsTheBallWithinTwentyFiveMillimetresOfTheCupsTarget) {
  std::unique_ptr<Env> env = make("BallInCupCatch-v0", {{"obs_mode", "state"}});
  const Plan plan = plan_catch(4);
  env->reset(4);
  int in = 0;
  for (int t = 0; t < 300; ++t) {
    const std::size_t knot = static_cast<std::size_t>(t / kKnotSteps);
    const StepResult step = env->step(in > 0 ? action(0, 0) : action(plan[knot][0], plan[knot][1]));
    const engine::World& world = world_of(*env);
    const engine::RobotId robot{0};
    const engine::RobotModel& model = world.robot_model(robot);
    // dm_control's in_target, written out from the two bodies' positions.
    const Eigen::Vector3d ball = world.link_pose(robot, model.link_index("ball")).translation();
    const Eigen::Vector3d cup = world.link_pose(robot, model.link_index("cup")).translation();
    const bool expected =
        std::abs(ball.x() - cup.x()) < 0.025 && std::abs(ball.z() - (cup.z() - 0.05)) < 0.025;
    ASSERT_EQ(step.reward, expected ? 1.0 : 0.0) << "step " << t;
    ASSERT_EQ(task_of(*env).in_cup(world), expected);
    // The state is dm_control's qpos: the cup from (0, 0.6), the ball from (0, 0.2).
    ASSERT_FLOAT_EQ(state(step.obs, "joint_pos", 0), cup.x());
    ASSERT_NEAR(state(step.obs, "joint_pos", 1), cup.z() - 0.6, 1e-6);
    ASSERT_FLOAT_EQ(state(step.obs, "joint_pos", 2), ball.x());
    ASSERT_NEAR(state(step.obs, "joint_pos", 3), ball.z() - 0.2, 1e-6);
    in += expected ? 1 : 0;
  }
  EXPECT_GT(in, 50);  // both sides of the test are seen
  EXPECT_LT(in, 300);
}

TEST(BallInCupTest, EpisodesStartAtRestWithTheBallFreeOfTheCup) {
  std::unique_ptr<Env> env = make("BallInCupCatch-v0", {{"obs_mode", "state"}});
  std::vector<double> xs;
  std::vector<double> zs;
  for (std::uint64_t seed = 0; seed < 30; ++seed) {
    const Value obs = env->reset(seed).obs;
    for (int j = 0; j < 4; ++j) EXPECT_EQ(state(obs, "joint_vel", j), 0.0);
    EXPECT_EQ(state(obs, "joint_pos", 0), 0.0);
    EXPECT_EQ(state(obs, "joint_pos", 1), 0.0);
    const double x = state(obs, "joint_pos", 2);
    const double z = state(obs, "joint_pos", 3);
    EXPECT_GE(x, -0.2);
    EXPECT_LE(x, 0.2);
    EXPECT_GE(z, 0.2);
    EXPECT_LE(z, 0.5);
    auto& world = const_cast<engine::World&>(world_of(*env));
    EXPECT_TRUE(world.detect_contacts().empty()) << "seed " << seed;
    xs.push_back(x);
    zs.push_back(z);
  }
  const auto spread = [](const std::vector<double>& v) {
    const auto [low, high] = std::minmax_element(v.begin(), v.end());
    return *high - *low;
  };
  EXPECT_GT(spread(xs), 0.3);
  EXPECT_GT(spread(zs), 0.2);
}

TEST(BallInCupTest, TheStringHoldsTheBallThreeTenthsOfAMetreFromTheCupsBottom) {
  std::unique_ptr<Env> env = make("BallInCupCatch-v0", {{"obs_mode", "state"}});
  env->reset(1);
  // Left alone the ball falls, swings and comes to hang under the cup: the string taut, stretched
  // by the ball's weight over its 1,635 N/m (0.4 mm), the cup sagging on its springs under both
  // weights (0.13 kg x 9.81 / 20 N/m = 64 mm).
  for (int t = 0; t < 900; ++t) env->step(action(0, 0));
  const engine::World& world = world_of(*env);
  EXPECT_NEAR(world.string_length(0), 0.3 + 0.0654 * 9.81 / 1635.0, 2e-4);
  const Value obs = env->step(action(0, 0)).obs;
  EXPECT_NEAR(state(obs, "joint_pos", 1), -0.064, 0.003);
  EXPECT_NEAR(state(obs, "joint_pos", 2), state(obs, "joint_pos", 0), 0.01);  // right under it
  // Shaken as hard as the motors go, it stretches by millimetres (0.306 m at most here) and never
  // runs away.
  env->reset(2);
  Rng rng(2);
  double longest = 0.0;
  for (int t = 0; t < 999; ++t) {
    env->step(action(rng.uniform() < 0.5 ? -1 : 1, rng.uniform() < 0.5 ? -1 : 1));
    longest = std::max(longest, world_of(*env).string_length(0));
  }
  EXPECT_LT(longest, 0.31);
}

TEST(BallInCupTest, CameraZeroIsDmControlsFixedOne) {
  std::unique_ptr<Env> env = make("BallInCupCatch-v0", {{"obs_mode", "state"}});
  env->reset(0);
  const render::Camera camera = task_of(*env).camera("cam0", world_of(*env));
  EXPECT_TRUE(camera.X_world_camera.translation().isApprox(Eigen::Vector3f(0.0F, -1.0F, 0.8F)));
  const Eigen::Vector3f forward = -camera.X_world_camera.linear().col(2);
  EXPECT_TRUE(forward.isApprox(Eigen::Vector3f(0.0F, 2.0F, -1.0F).normalized(), 1e-5F));
  EXPECT_EQ(camera.fov_y_deg, 45.0F);
}

}  // namespace
}  // namespace pixelgym
