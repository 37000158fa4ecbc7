#include "pixelgym/envs/tasks/pendulum.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "pixelgym/engine/world.h"
#include "pixelgym/envs/registry.h"
#include "tests/envs/tasks/scripted.h"

namespace pixelgym {
namespace {

using testing::state;

// Pump energy with full torque along the motion; near upright, hold with PD.
Value swing_up(const Value& obs) {
  const double phi = state(obs, "joint_pos", 0);  // 0 upright
  const double omega = state(obs, "joint_vel", 0);
  double u;
  if (std::abs(phi) < 0.3) {
    u = (-12.0 * phi - 2.0 * omega) / PendulumTask::kMaxTorqueNm;
  } else {
    // Energy relative to resting upright: J w^2 / 2 + m g d (cos(phi) - 1).
    const double energy = 0.5 * 0.2594 * omega * omega + 5.151 * (std::cos(phi) - 1.0);
    u = energy < 0.0 ? (omega >= 0.0 ? 1.0 : -1.0) : -0.3 * (omega >= 0.0 ? 1.0 : -1.0);
  }
  return Array::from_vector<float>({1}, {static_cast<float>(std::clamp(u, -1.0, 1.0))});
}

TEST(PendulumTest, EnergyPumpingSwingsUpAndHolds) {
  std::unique_ptr<Env> env = make("PendulumSwingup-v0", {{"obs_mode", "state"}});
  double scripted = 0.0;
  double random = 0.0;
  for (std::uint64_t seed = 0; seed < 3; ++seed) {
    scripted += testing::episode_return(*env, seed, swing_up) / 3.0;
    random += testing::episode_return(*env, seed, testing::random_policy(*env, seed)) / 3.0;
  }
  std::cout << "PendulumSwingup-v0 mean return over 3 episodes: scripted " << scripted
            << ", random " << random << "\n";
  EXPECT_GE(scripted, 700.0);
  EXPECT_LT(random, 100.0);
}

// The reward is 1 within 30 degrees of upright and 0 beyond: sampled on both sides of the edge,
// on both sides of upright, and far from it (a zone narrowed to 15 or widened to 90 degrees
// fails here).
TEST(PendulumTest, RewardZoneIsThirtyDegreesEachSide) {
  PendulumTask task;
  engine::World world(task.world_config());
  task.build(world);
  const engine::RobotId pendulum{0};  // the task's only robot
  const double degree = 3.14159265358979 / 180.0;
  for (const double from_upright_deg :
       {0.0, 10.0, 20.0, 29.0, 29.9, 30.1, 31.0, 45.0, 89.0, 91.0, 135.0, 180.0}) {
    for (const double sign : {1.0, -1.0}) {
      // Joint angle 0 hangs down; upright is pi.
      const double q = 3.14159265358979 + sign * from_upright_deg * degree;
      world.set_joint_state(pendulum, Eigen::Matrix<double, 1, 1>(q),
                            Eigen::Matrix<double, 1, 1>(0.0));
      ASSERT_NEAR(std::abs(task.angle_from_upright(world)), from_upright_deg * degree, 1e-9);
      EXPECT_EQ(task.reward(world), from_upright_deg < 30.0 ? 1.0 : 0.0)
          << sign * from_upright_deg << " degrees from upright";
    }
  }
}

TEST(PendulumTest, RewardOnlyNearUpright) {
  std::unique_ptr<Env> env = make("PendulumSwingup-v0", {{"obs_mode", "state"}});
  env->reset(0);
  const StepResult step = env->step(Array::from_vector<float>({1}, {0.0F}));
  const double phi = state(step.obs, "joint_pos", 0);
  EXPECT_EQ(step.reward, std::cos(phi) >= std::cos(3.14159265358979 / 6) ? 1.0 : 0.0);
}

}  // namespace
}  // namespace pixelgym
