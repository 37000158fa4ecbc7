#include "pixelgym/envs/tasks/reacher.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>

#include "pixelgym/engine/world.h"
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
  }
  // Ten random episodes: with -v1's damped joints random torques barely move the arm, so an
  // episode that starts beside the target scores hundreds and three episodes are too few.
  for (std::uint64_t seed = 0; seed < 10; ++seed) {
    random += testing::episode_return(*env, seed, testing::random_policy(*env, seed)) / 10.0;
  }
  std::cout << GetParam() << " mean return: scripted " << scripted << " (3 episodes), random "
            << random << " (10)\n";
  EXPECT_GE(scripted, 850.0);
  EXPECT_LT(random, 150.0);
}

INSTANTIATE_TEST_SUITE_P(EasyAndHard, ReacherTest,
                         ::testing::Values("ReacherEasy-v0", "ReacherHard-v0", "ReacherEasy-v1",
                                           "ReacherHard-v1"),
                         [](const ::testing::TestParamInfo<const char*>& param_info) {
                           std::string name = param_info.param;
                           name[name.find('-')] = '_';
                           return name;
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

// -v1 targets lie 0.05 to 0.20 m from the shoulder, as dm_control draws them.
TEST(ReacherTargetTest, V1TargetsLieAsDmControlsDo) {
  std::unique_ptr<Env> env = make("ReacherEasy-v1", {{"obs_mode", "state"}});
  const auto& pixel_env = static_cast<PixelEnv&>(env->unwrapped());
  const auto& task = static_cast<const ReacherTask&>(pixel_env.task());
  double farthest = 0.0;
  for (std::uint64_t seed = 0; seed < 200; ++seed) {
    env->reset(seed);
    const double r = task.target(pixel_env.world()).head<2>().norm();
    EXPECT_GE(r, 0.05 - 1e-9);
    farthest = std::max(farthest, r);
  }
  EXPECT_LE(farthest, 0.20 + 1e-9);
  EXPECT_GT(farthest, 0.19);  // -v0 draws up to 0.22: 15 of 200 beyond 0.20 would fail above
}

// Puts the fingertip `distance_m` from the target's centre, beside it (two-link inverse
// kinematics), and returns the task's reward there.
double reward_at(const char* id, double distance_m) {
  std::unique_ptr<Env> env = make(id, {{"obs_mode", "state"}});
  const auto& task =
      static_cast<const ReacherTask&>(static_cast<PixelEnv&>(env->unwrapped()).task());
  ReacherTask copy = task;  // a task of the same id, on a world of its own
  engine::World world(copy.world_config());
  copy.build(world);
  Rng rng(5);
  copy.initialize_episode(world, rng);
  const Eigen::Vector2d target = copy.target(world).head<2>();
  const Eigen::Vector2d side = Eigen::Vector2d(-target.y(), target.x()).normalized();
  const Eigen::Vector2d p = target + distance_m * side;
  const double c2 = (p.squaredNorm() - 2 * kLink * kLink) / (2 * kLink * kLink);
  const double elbow = std::acos(std::clamp(c2, -1.0, 1.0));
  const double shoulder = std::atan2(p.y(), p.x()) -
                          std::atan2(kLink * std::sin(elbow), kLink + kLink * std::cos(elbow));
  world.set_joint_state(engine::RobotId{0}, Eigen::Vector2d(shoulder, elbow),
                        Eigen::Vector2d::Zero());
  EXPECT_NEAR((copy.target(world) - copy.fingertip(world)).head<2>().norm(), distance_m, 1e-6)
      << id;
  return copy.reward(world);
}

// dm_control rewards a fingertip within the target radius plus its finger's 0.01 m: -v1 does,
// -v0 counts the target radius alone. Both sides of each bound.
TEST(ReacherRewardTest, V1CountsTheFingerRadiusAsDmControl) {
  EXPECT_EQ(reward_at("ReacherEasy-v0", 0.049), 1.0);
  EXPECT_EQ(reward_at("ReacherEasy-v0", 0.055), 0.0);
  EXPECT_EQ(reward_at("ReacherEasy-v1", 0.055), 1.0);
  EXPECT_EQ(reward_at("ReacherEasy-v1", 0.061), 0.0);
  EXPECT_EQ(reward_at("ReacherHard-v0", 0.014), 1.0);
  EXPECT_EQ(reward_at("ReacherHard-v0", 0.02), 0.0);
  EXPECT_EQ(reward_at("ReacherHard-v1", 0.024), 1.0);
  EXPECT_EQ(reward_at("ReacherHard-v1", 0.026), 0.0);
}

// Shoulder speed after holding full shoulder torque for `seconds` from reset(0) (at rest).
double shoulder_speed_after(const char* id, double seconds) {
  std::unique_ptr<Env> env = make(id, {{"obs_mode", "state"}});
  env->reset(0);
  const Value push = Array::from_vector<float>({2}, {1.0F, 0.0F});
  Value obs;
  for (int step = 0; step < static_cast<int>(seconds / 0.02); ++step) obs = env->step(push).obs;
  return state(obs, "joint_vel", 0);
}

// dm_control damps each joint with 0.01 N m s/rad: a full torque of 0.05 N m settles near 5 rad/s
// (the arm turning as one, the wrist straightened). -v0 has no damping and keeps accelerating.
TEST(ReacherDynamicsTest, V1JointsAreDampedAsDmControls) {
  const double v1 = shoulder_speed_after("ReacherEasy-v1", 3.0);
  const double v0 = shoulder_speed_after("ReacherEasy-v0", 3.0);
  std::cout << "shoulder speed after 3 s of full torque: v1 " << v1 << " rad/s, v0 " << v0
            << " rad/s\n";
  EXPECT_NEAR(v1, 5.0, 0.5);
  EXPECT_GT(v0, 20.0);
}

// Pixels of a 64 x 64 anti-aliased frame after reset(seed) whose grey level (0.299 R + 0.587 G +
// 0.114 B) is at least 230. Apart from -v1's white fingertip, only a rare highlight on the yellow
// hand is that bright (at 200, v0's hand gave 20 such pixels over the 8 frames below).
int bright_grey_pixels(const std::string& id, std::uint64_t seed) {
  auto env = make(id, {{"width", 64}, {"height", 64}, {"obs_mode", "pixels"}, {"msaa", 4}});
  const Array frame = env->reset(seed).obs.dict().at("pixels").array();
  const std::uint8_t* p = frame.data<std::uint8_t>();
  int count = 0;
  for (int i = 0; i < 64 * 64; ++i) {
    if (0.299 * p[3 * i] + 0.587 * p[3 * i + 1] + 0.114 * p[3 * i + 2] >= 230.0) ++count;
  }
  return count;
}

// -v0's red fingertip has the floor's grey level and is about a pixel wide at 64 x 64, so grey
// frames hide it; -v1 draws it white and 0.02 m in radius, a bright spot of several pixels in
// most frames (fewer where the hand's shadow or the target covers part of it). Over 8 seeds.
TEST(ReacherDrawingTest, V1FingertipStandsOutInGrey) {
  int v0 = 0;
  int v1 = 0;
  int v1_frames_with_spot = 0;
  for (std::uint64_t seed = 0; seed < 8; ++seed) {
    v0 += bright_grey_pixels("ReacherEasy-v0", seed);
    const int spot = bright_grey_pixels("ReacherEasy-v1", seed);
    v1 += spot;
    if (spot >= 3) ++v1_frames_with_spot;
  }
  std::cout << "bright grey pixels over 8 frames: v0 " << v0 << ", v1 " << v1 << " ("
            << v1_frames_with_spot << " frames with a spot of 3 or more)\n";
  EXPECT_LE(v0, 4);                   // measured: 1
  EXPECT_GE(v1, 16);                  // measured: 24
  EXPECT_GE(v1_frames_with_spot, 5);  // measured: 6 of 8
}

}  // namespace
}  // namespace pixelgym
