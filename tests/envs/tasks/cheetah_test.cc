#include "pixelgym/envs/tasks/cheetah.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <memory>

#include "pixelgym/engine/world.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "tests/envs/tasks/scripted.h"
#include "tests/envs/tasks/trained_policy.h"

namespace pixelgym {
namespace {

// An open-loop gait: leg j's action at control step t is
// clip(amplitude_j sin(2 pi frequency t 0.01 s + phase_j) + offset_j, -1, 1), found by
// tests/envs/tasks/controllers/cheetah_gait_search.py (the cross-entropy method on seeds 0 and
// 1; mean return 269.7 there).
struct Gait {
  double frequency_hz = 1.9240;
  std::array<double, 6> amplitude{1.1739, 0.5140, 0.8714, 1.2212, 0.7569, 0.2003};
  std::array<double, 6> phase{2.7819, 2.2437, 2.2637, 3.6137, 1.2256, -1.7166};
  std::array<double, 6> offset{0.3462, -0.3358, -0.3342, -0.4970, -1.0689, 0.4524};
};

std::function<Value(const Value&)> gait_policy() {
  auto step = std::make_shared<int>(0);
  return [step](const Value&) {
    const Gait gait;
    const double t = 0.01 * (*step)++;
    std::vector<float> action(6);
    for (std::size_t j = 0; j < 6; ++j) {
      action[j] = static_cast<float>(std::clamp(
          gait.amplitude[j] * std::sin(2 * M_PI * gait.frequency_hz * t + gait.phase[j]) +
              gait.offset[j],
          -1.0, 1.0));
    }
    return Value(Array::from_vector<float>({6}, action));
  };
}

const CheetahTask& task_of(Env& env) {
  return dynamic_cast<const CheetahTask&>(dynamic_cast<PixelEnv&>(env.unwrapped()).task());
}

const engine::World& world_of(Env& env) { return dynamic_cast<PixelEnv&>(env.unwrapped()).world(); }

TEST(CheetahTest, AGaitRunsFarAboveRandomActions) {
  std::unique_ptr<Env> env = make("CheetahRun-v0", {{"obs_mode", "state"}});
  double gait = 0.0;
  double random = 0.0;
  // Seeds the gait was not searched on.
  for (std::uint64_t seed = 2; seed < 5; ++seed) {
    gait += testing::episode_return(*env, seed, gait_policy()) / 3.0;
    random += testing::episode_return(*env, seed, testing::random_policy(*env, seed)) / 3.0;
  }
  std::cout << "CheetahRun-v0 mean return over seeds 2-4: gait " << gait << ", random " << random
            << "\n";
  EXPECT_GE(gait, 200.0);  // a mean speed of 2 m/s
  EXPECT_LE(random, 30.0);
}

// A policy trained from state (drq, action repeat 4, seed 0, 100k env steps = 400k control
// steps), exported from its run's last checkpoint; the command is in controllers/README.md.
TEST(CheetahTest, ATrainedPolicyRunsFarAboveRandomActions) {
  const testing::TrainedAndRandom played = testing::play_trained_policy("cheetah_run.policy.json");
  ASSERT_EQ(played.env_id, "CheetahRun-v0");
  EXPECT_GE(played.trained, 550.0);  // a mean speed of 5.5 m/s
  EXPECT_LE(played.random, 30.0);
}

TEST(CheetahTest, TheRewardIsTheCentreOfMassSpeedOverTenClipped) {
  std::unique_ptr<Env> env = make("CheetahRun-v0", {{"obs_mode", "state"}});
  env->reset(0);
  const auto policy = gait_policy();
  Value obs;
  int fast = 0;
  for (int t = 0; t < 400; ++t) {
    const StepResult step = env->step(policy(obs));
    const double speed = world_of(*env).center_of_mass_velocity(engine::RobotId{0}).x();
    ASSERT_DOUBLE_EQ(task_of(*env).speed(world_of(*env)), speed);
    ASSERT_NEAR(step.reward, std::clamp(speed / 10.0, 0.0, 1.0), 1e-12) << "step " << t;
    fast += speed > 1.0 ? 1 : 0;
  }
  EXPECT_GT(fast, 100);  // the gait runs forward, so the clip is not all that is tested
}

TEST(CheetahTest, EpisodesStartSettledFromRandomLegAngles) {
  std::unique_ptr<Env> env = make("CheetahRun-v0", {{"obs_mode", "state"}});
  const engine::RobotModel* model = nullptr;
  std::vector<double> first_thigh;
  for (std::uint64_t seed = 0; seed < 4; ++seed) {
    const Value obs = env->reset(seed).obs;
    const engine::World& world = world_of(*env);
    model = &world.robot_model(engine::RobotId{0});
    // After 2 s without torque it rests: slow, the torso above the ground, the legs in range.
    for (int j = 0; j < 9; ++j) {
      EXPECT_LT(std::abs(testing::state(obs, "joint_vel", j)), 0.5)
          << "seed " << seed << " dof " << j;
    }
    EXPECT_GT(0.7 + testing::state(obs, "joint_pos", 0), 0.2) << "torso height, seed " << seed;
    for (int dof = 3; dof < 9; ++dof) {
      const engine::JointModel& joint =
          model->joints()[static_cast<std::size_t>(model->movable_joints()[dof])];
      const double q = testing::state(obs, "joint_pos", dof - 1);
      EXPECT_GE(q, joint.lower - 0.05) << joint.name;
      EXPECT_LE(q, joint.upper + 0.05) << joint.name;
    }
    first_thigh.push_back(testing::state(obs, "joint_pos", 2));
  }
  // Different seeds, different starts.
  std::sort(first_thigh.begin(), first_thigh.end());
  EXPECT_GT(first_thigh.back() - first_thigh.front(), 0.05);
}

TEST(CheetahTest, TheSideCameraFollowsTheCentreOfMass) {
  std::unique_ptr<Env> env = make("CheetahRun-v0", {{"obs_mode", "state"}});
  env->reset(2);
  const auto policy = gait_policy();
  Value obs;
  for (int t = 0; t < 600; ++t) env->step(policy(obs));
  const engine::World& world = world_of(*env);
  const Eigen::Vector3d com = world.center_of_mass(engine::RobotId{0});
  ASSERT_GT(com.x(), 5.0);  // it ran
  const render::Camera camera = task_of(*env).camera("side", world);
  const Eigen::Vector3f eye = camera.X_world_camera.translation();
  EXPECT_NEAR(eye.x(), com.x() - 0.0378, 1e-3);
  EXPECT_NEAR(eye.y(), -3.0, 1e-4);
  EXPECT_NEAR(eye.z(), com.z() + 0.149, 1e-3);
}

}  // namespace
}  // namespace pixelgym
