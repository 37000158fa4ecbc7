// UrdfReach-v0 on two arms: the project's 7-DOF mesh arm (the default) and a 4-DOF arm written for
// this test (tests/data/urdf_good/telescope_arm.urdf: revolute and prismatic joints, primitives).
// On each, every target can be reached (joint positions found for it are driven to), and a bad URDF
// or a wrong link name is an error naming the problem.
#include "pixelgym/envs/tasks/urdf_reach.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "pixelgym/engine/robot_model.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "tests/envs/tasks/scripted.h"

namespace pixelgym {
namespace {

using ::testing::HasSubstr;

const std::string kTelescope =
    std::string(PIXELGYM_SOURCE_DIR) + "/tests/data/urdf_good/telescope_arm.urdf";

std::unique_ptr<Env> make_reach(const std::string& urdf, const std::string& end_link) {
  Params kwargs = {{"obs_mode", "state"}};
  if (!urdf.empty()) kwargs.insert_or_assign("urdf", urdf);
  if (!end_link.empty()) kwargs.insert_or_assign("end_link", end_link);
  return make("UrdfReach-v0", kwargs);
}

const UrdfReachTask& task_of(Env& env) {
  return static_cast<const UrdfReachTask&>(static_cast<PixelEnv&>(env.unwrapped()).task());
}

// Joint positions within the limits that put the end link at `target`: damped least squares on the
// task's own forward kinematics, clamped to the limits, from seeded random starts. Empty when none
// of them gets within 1 mm.
std::optional<Eigen::VectorXd> solve_ik(const UrdfReachTask& task, const Eigen::Vector3d& target) {
  const auto dofs = static_cast<int>(task.joint_speeds().size());
  Rng rng(1);
  for (int start = 0; start < 50; ++start) {
    Eigen::VectorXd q(dofs);
    for (int d = 0; d < dofs; ++d) q[d] = rng.uniform(task.lower(d), task.upper(d));
    for (int iteration = 0; iteration < 300; ++iteration) {
      const Eigen::Vector3d error = target - task.end_link_position(q);
      if (error.norm() < 1e-3) return q;
      Eigen::MatrixXd jacobian(3, dofs);
      constexpr double kStep = 1e-6;
      for (int d = 0; d < dofs; ++d) {
        Eigen::VectorXd moved = q;
        moved[d] += kStep;
        jacobian.col(d) = (task.end_link_position(moved) - task.end_link_position(q)) / kStep;
      }
      const Eigen::Matrix3d damped =
          jacobian * jacobian.transpose() + 1e-4 * Eigen::Matrix3d::Identity();
      q += jacobian.transpose() * damped.ldlt().solve(error);
      for (int d = 0; d < dofs; ++d) q[d] = std::clamp(q[d], task.lower(d), task.upper(d));
    }
  }
  return std::nullopt;
}

// Solves for joint positions that reach the episode's target (once per target), then drives the
// joints there in a straight line in joint space, which stays within the limits.
std::function<Value(const Value&)> reaching_policy(Env& env) {
  const UrdfReachTask* task = &task_of(env);
  const auto dofs = static_cast<int>(task->joint_speeds().size());
  auto goal = std::make_shared<std::pair<Eigen::Vector3d, Eigen::VectorXd>>();
  return [task, dofs, goal](const Value& obs) {
    Eigen::VectorXd q(dofs);
    for (int d = 0; d < dofs; ++d) q[d] = testing::state(obs, "joint_pos", d);
    Eigen::Vector3d target;
    for (int i = 0; i < 3; ++i) target[i] = testing::state(obs, "target_pos", i);
    if (goal->second.size() == 0 || !goal->first.isApprox(target)) {
      const std::optional<Eigen::VectorXd> solution = solve_ik(*task, target);
      EXPECT_TRUE(solution) << "no joint positions reach " << target.transpose();
      *goal = {target, solution ? *solution : q};
    }
    std::vector<float> action(static_cast<std::size_t>(dofs));
    for (int d = 0; d < dofs; ++d) {
      const double velocity = 4.0 * (goal->second[d] - q[d]);
      action[static_cast<std::size_t>(d)] =
          static_cast<float>(std::clamp(velocity / task->joint_speeds()[d], -1.0, 1.0));
    }
    return Array::from_vector<float>({dofs}, action);
  };
}

struct Arm {
  std::string urdf;  // empty: the default
  std::string end_link;
  int dofs;
};

class UrdfReachArmTest : public ::testing::TestWithParam<Arm> {};

// Every episode's target is one the end link can reach: joint positions within the limits are
// found for it, and driving the joints there holds the reward at 1 over the last 100 steps, far
// above a random policy.
TEST_P(UrdfReachArmTest, EveryTargetIsReached) {
  const Arm& arm = GetParam();
  auto env = make_reach(arm.urdf, arm.end_link);
  ASSERT_EQ(env->action_space().shape(), std::optional<Shape>(Shape{arm.dofs}));
  const auto policy = reaching_policy(*env);
  double scripted = 0.0;
  double random = 0.0;
  constexpr int kEpisodes = 8;
  for (std::uint64_t seed = 0; seed < kEpisodes; ++seed) {
    Value obs = env->reset(seed).obs;
    int at_target = 0;
    double total = 0.0;
    for (int t = 0;; ++t) {
      const StepResult step = env->step(policy(obs));
      total += step.reward;
      if (t >= 400) at_target += step.reward > 0.99;
      obs = step.obs;
      if (step.terminated || step.truncated) break;
    }
    EXPECT_GE(at_target, 99) << "seed " << seed << ": the end link did not reach the target";
    scripted += total / kEpisodes;
    random += testing::episode_return(*env, seed, testing::random_policy(*env, seed)) / kEpisodes;
  }
  std::cout << "UrdfReach-v0 on " << (arm.urdf.empty() ? "arm/arm.urdf" : arm.urdf) << " (reach "
            << task_of(*env).reach_m() << " m): driven to solved joint positions " << scripted
            << ", random " << random << " over " << kEpisodes << " episodes\n";
  EXPECT_GT(scripted, 5.0 * random);
}

INSTANTIATE_TEST_SUITE_P(BothArms, UrdfReachArmTest,
                         ::testing::Values(Arm{"", "", 7}, Arm{kTelescope, "gripper", 4}),
                         [](const ::testing::TestParamInfo<Arm>& arm) {
                           return arm.param.urdf.empty() ? std::string("ProjectArm")
                                                         : std::string("TelescopeArm");
                         });

// The default is ArmReach-v0's arm, with that task's spaces.
TEST(UrdfReachTest, TheDefaultIsTheProjectArm) {
  auto env = make_reach("", "");
  EXPECT_EQ(env->observation_space().to_string(),
            make("ArmReach-v0", {{"obs_mode", "state"}})->observation_space().to_string());
  EXPECT_GT(task_of(*env).reach_m(), 0.5);
}

TEST(UrdfReachTest, BadUrdfsAndWrongLinksAreErrorsNamingTheProblem) {
  const auto message = [](const std::string& urdf, const std::string& end_link) {
    try {
      make_reach(urdf, end_link);
    } catch (const std::exception& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(message("/no/such/arm.urdf", "tip"),
              HasSubstr("urdf \"/no/such/arm.urdf\" is not a file, nor one in the asset folders"));
  const std::string malformed =
      std::string(PIXELGYM_SOURCE_DIR) + "/tests/data/urdf/malformed_xml.urdf";
  EXPECT_THAT(message(malformed, "tip"), HasSubstr("malformed_xml.urdf"));
  EXPECT_THAT(message(kTelescope, "hand"),
              HasSubstr("has no link \"hand\"; its links: pedestal, column, upper_arm, forearm, "
                        "slider, gripper"));
  EXPECT_THAT(message(kTelescope, "pedestal"),
              HasSubstr("link \"pedestal\" of " + kTelescope + " cannot move"));
  EXPECT_THROW(make_reach(malformed, "tip"), engine::UrdfError);
}

}  // namespace
}  // namespace pixelgym
