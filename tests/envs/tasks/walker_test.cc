#include "pixelgym/envs/tasks/walker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <vector>

#include "pixelgym/engine/world.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "tests/envs/tasks/scripted.h"
#include "tests/envs/tasks/trained_policy.h"

namespace pixelgym {
namespace {

using testing::state;

PixelEnv& pixel_env(Env& env) { return dynamic_cast<PixelEnv&>(env.unwrapped()); }
const WalkerTask& task_of(Env& env) {
  return dynamic_cast<const WalkerTask&>(pixel_env(env).task());
}

Value action(std::vector<float> values) { return Array::from_vector<float>({6}, values); }

// dm_control's reward, written out from its definition (suite/walker.py).
double dm_reward(double height, double upright_zz, double speed, double walk_speed) {
  const double standing = height >= 1.2 ? 1.0 : std::pow(0.1, std::pow((1.2 - height) / 0.6, 2.0));
  const double stand = (3.0 * standing + (1.0 + upright_zz) / 2.0) / 4.0;
  if (walk_speed == 0.0) return stand;
  return stand * (5.0 * std::clamp(speed, 0.0, 1.0) + 1.0) / 6.0;
}

class WalkerTest : public ::testing::TestWithParam<const char*> {};

TEST_P(WalkerTest, TheRewardIsDmControlsStandTimesMove) {
  std::unique_ptr<Env> env = make(GetParam(), {{"obs_mode", "state"}});
  const double walk_speed = std::string(GetParam()) == "WalkerWalk-v0" ? 1.0 : 0.0;
  for (std::uint64_t seed = 0; seed < 3; ++seed) {
    env->reset(seed);
    const auto policy = testing::random_policy(*env, seed);
    Value obs;
    for (int t = 0; t < 200; ++t) {
      const StepResult step = env->step(policy(obs));
      const engine::World& world = pixel_env(*env).world();
      const WalkerTask& task = task_of(*env);
      const double expected = dm_reward(task.torso_height(world), task.torso_upright(world),
                                        task.speed(world), walk_speed);
      ASSERT_NEAR(step.reward, expected, 1e-9) << GetParam() << " seed " << seed << " step " << t;
      ASSERT_FLOAT_EQ(state(step.obs, "height", 0), task.torso_height(world));
    }
  }
}

// Policies trained from state (drq, action repeat 2, seed 0, 100k env steps = 200k control
// steps), exported from the runs' last checkpoints; the commands are in controllers/README.md.
TEST_P(WalkerTest, ATrainedPolicyScoresFarAboveRandomActions) {
  const bool walk = std::string(GetParam()) == "WalkerWalk-v0";
  const testing::TrainedAndRandom played =
      testing::play_trained_policy(walk ? "walker_walk.policy.json" : "walker_stand.policy.json");
  ASSERT_EQ(played.env_id, GetParam());
  EXPECT_GE(played.trained, walk ? 900.0 : 950.0);
  EXPECT_LE(played.random, walk ? 60.0 : 250.0);
}

INSTANTIATE_TEST_SUITE_P(
    Walker, WalkerTest, ::testing::Values("WalkerStand-v0", "WalkerWalk-v0"),
    [](const ::testing::TestParamInfo<const char*>& param_info) {
      return std::string(param_info.param).substr(0, std::string(param_info.param).find('-'));
    });

TEST(WalkerTaskTest, EpisodesStartAtAHeightOf1Point3WithARandomPitch) {
  std::unique_ptr<Env> env = make("WalkerStand-v0", {{"obs_mode", "state"}});
  std::vector<double> pitches;
  for (std::uint64_t seed = 0; seed < 6; ++seed) {
    const Value obs = env->reset(seed).obs;
    EXPECT_NEAR(state(obs, "height", 0), 1.3, 1e-6);     // float32
    EXPECT_NEAR(state(obs, "joint_pos", 0), 0.0, 1e-9);  // rootz
    // The torso's orientation entries are (cos, sin) of its pitch, which is rooty.
    const double pitch = state(obs, "joint_pos", 1);
    EXPECT_NEAR(state(obs, "orientations", 0), std::cos(pitch), 1e-6);
    EXPECT_NEAR(std::abs(state(obs, "orientations", 1)), std::abs(std::sin(pitch)), 1e-6);
    pitches.push_back(pitch);
    for (int j = 0; j < 9; ++j) EXPECT_EQ(state(obs, "joint_vel", j), 0.0F);
  }
  std::sort(pitches.begin(), pitches.end());
  EXPECT_GT(pitches.back() - pitches.front(), 1.0);  // spread over [-pi, pi)
}

TEST(WalkerTaskTest, ActionsAndStateFollowDmControlsJointOrder) {
  // Action 0 is the right hip, action 3 the left hip; joint_pos[2] and [5] are their angles.
  // One hip's full torque for 2 control steps, against none, from a start with both hips away
  // from their limits: that hip turns most (the other turns too, as the torso turns back).
  std::unique_ptr<Env> env = make("WalkerStand-v0", {{"obs_mode", "state"}});
  std::uint64_t seed = 0;
  for (;; ++seed) {
    ASSERT_LT(seed, 100U) << "no start with both hips mid-range";
    const Value obs = env->reset(seed).obs;
    const auto mid = [](double q) { return q > -0.35 + 0.5 && q < 1.75 - 0.5; };
    if (mid(state(obs, "joint_pos", 2)) && mid(state(obs, "joint_pos", 5))) break;
  }
  const auto hips_after = [&](int pushed) {
    env->reset(seed);
    std::vector<float> a(6, 0.0F);
    if (pushed >= 0) a[static_cast<std::size_t>(pushed)] = 1.0F;
    Value obs;
    for (int t = 0; t < 2; ++t) obs = env->step(action(a)).obs;
    return std::make_pair(state(obs, "joint_pos", 2), state(obs, "joint_pos", 5));
  };
  const auto [right0, left0] = hips_after(-1);
  const auto [right_r, left_r] = hips_after(0);
  const auto [right_l, left_l] = hips_after(3);
  std::cout << "seed " << seed << ": right hip pushed: right " << right_r - right0 << ", left "
            << left_r - left0 << "; left pushed: right " << right_l - right0 << ", left "
            << left_l - left0 << " rad\n";
  EXPECT_GT(std::abs(right_r - right0), 1.3 * std::abs(left_r - left0));
  EXPECT_GT(std::abs(left_l - left0), 1.3 * std::abs(right_l - right0));
  // And the state is in dm_control's order by the joints' names.
  const Value obs = env->reset(seed).obs;
  const engine::World& world = pixel_env(*env).world();
  const engine::RobotModel& model = world.robot_model(engine::RobotId{0});
  const char* order[] = {"rootz",       "rooty",    "right_hip", "right_knee",
                         "right_ankle", "left_hip", "left_knee", "left_ankle"};
  for (int i = 0; i < 8; ++i) {
    int dof = -1;
    for (std::size_t d = 0; d < model.movable_joints().size(); ++d) {
      if (model.joints()[static_cast<std::size_t>(model.movable_joints()[d])].name == order[i]) {
        dof = static_cast<int>(d);
      }
    }
    ASSERT_GE(dof, 0) << order[i];
    EXPECT_FLOAT_EQ(state(obs, "joint_pos", i),
                    static_cast<float>(world.joint_position(engine::RobotId{0}, dof)))
        << order[i];
  }
}

TEST(WalkerTaskTest, TheSideCameraFollowsTheCentreOfMass) {
  std::unique_ptr<Env> env = make("WalkerWalk-v0", {{"obs_mode", "state"}});
  env->reset(3);
  const auto policy = testing::random_policy(*env, 3);
  Value obs;
  for (int t = 0; t < 100; ++t) env->step(policy(obs));
  const engine::World& world = pixel_env(*env).world();
  const Eigen::Vector3d com = world.center_of_mass(engine::RobotId{0});
  const Eigen::Vector3f eye = task_of(*env).camera("side", world).X_world_camera.translation();
  EXPECT_NEAR(eye.x(), com.x() - 0.0088, 1e-3);
  EXPECT_NEAR(eye.y(), -2.0, 1e-4);
  EXPECT_NEAR(eye.z(), com.z() + 1.2277, 1e-3);
}

}  // namespace
}  // namespace pixelgym
