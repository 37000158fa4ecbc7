#include "pixelgym/envs/tasks/reacher.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "tests/envs/tasks/scripted.h"

namespace pixelgym {
namespace {

using testing::state;

constexpr double kLink = 0.12;

// Two-link inverse kinematics to the target (elbow solution nearest the current one), then PD
// on the joint angles.
Value reach(const Value& obs) {
  const double q1 = state(obs, "joint_pos", 0);
  const double q2 = state(obs, "joint_pos", 1);
  const double tip_x = kLink * std::cos(q1) + kLink * std::cos(q1 + q2);
  const double tip_y = kLink * std::sin(q1) + kLink * std::sin(q1 + q2);
  const double tx = tip_x + state(obs, "to_target", 0);
  const double ty = tip_y + state(obs, "to_target", 1);
  const double r2 = tx * tx + ty * ty;
  const double c2 = std::clamp((r2 - 2 * kLink * kLink) / (2 * kLink * kLink), -1.0, 1.0);
  const double elbow = (q2 >= 0 ? 1.0 : -1.0) * std::acos(c2);
  const double shoulder =
      std::atan2(ty, tx) - std::atan2(kLink * std::sin(elbow), kLink + kLink * std::cos(elbow));
  const auto wrap = [](double a) { return std::remainder(a, 2 * 3.14159265358979); };
  const double e1 = wrap(shoulder - q1);
  const double e2 = wrap(elbow - q2);
  const double u1 = 4.0 * e1 - 0.25 * state(obs, "joint_vel", 0);
  const double u2 = 4.0 * e2 - 0.25 * state(obs, "joint_vel", 1);
  return Array::from_vector<float>({2}, {static_cast<float>(std::clamp(u1, -1.0, 1.0)),
                                         static_cast<float>(std::clamp(u2, -1.0, 1.0))});
}

class ReacherTest : public ::testing::TestWithParam<const char*> {};

TEST_P(ReacherTest, InverseKinematicsReachesAndStaysOnTheTarget) {
  std::unique_ptr<Env> env = make(GetParam(), {{"obs_mode", "state"}});
  double scripted = 0.0;
  double random = 0.0;
  for (std::uint64_t seed = 0; seed < 3; ++seed) {
    scripted += testing::episode_return(*env, seed, reach) / 3.0;
    random += testing::episode_return(*env, seed, testing::random_policy(*env, seed)) / 3.0;
  }
  std::cout << GetParam() << " mean return over 3 episodes: scripted " << scripted << ", random "
            << random << "\n";
  EXPECT_GE(scripted, 850.0);
  EXPECT_LT(random, 150.0);
}

INSTANTIATE_TEST_SUITE_P(
    EasyAndHard, ReacherTest, ::testing::Values("ReacherEasy-v0", "ReacherHard-v0"),
    [](const ::testing::TestParamInfo<const char*>& param_info) {
      return std::string(param_info.param).substr(0, std::string(param_info.param).find('-'));
    });

TEST(ReacherTargetTest, TargetsAreWithinReachAndDifferAcrossSeeds) {
  std::unique_ptr<Env> env = make("ReacherEasy-v0", {{"obs_mode", "state"}});
  const auto& task =
      static_cast<const ReacherTask&>(static_cast<PixelEnv&>(env->unwrapped()).task());
  const auto& world = static_cast<PixelEnv&>(env->unwrapped()).world();
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (std::uint64_t seed = 0; seed < 10; ++seed) {
    env->reset(seed);
    const Eigen::Vector3d target = task.target(world);
    EXPECT_LE(target.head<2>().norm(), 0.22 + 1e-9);
    EXPECT_GE(target.head<2>().norm(), 0.05 - 1e-9);
    EXPECT_NE(target, previous);
    previous = target;
  }
}

}  // namespace
}  // namespace pixelgym
