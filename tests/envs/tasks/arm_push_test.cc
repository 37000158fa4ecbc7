#include "pixelgym/envs/tasks/arm_push.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <iostream>
#include <optional>

#include "pixelgym/engine/robot_model.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "tests/envs/tasks/scripted.h"

namespace pixelgym {
namespace {

Eigen::Vector3d vec3(const Value& obs, const std::string& key) {
  return {testing::state(obs, key, 0), testing::state(obs, key, 1), testing::state(obs, key, 2)};
}

// Cube and goal positions from the observation's relative vectors.
Eigen::Vector3d cube_of(const Value& obs) {
  return vec3(obs, "end_effector_pos") + vec3(obs, "to_cube");
}
Eigen::Vector3d goal_of(const Value& obs) {
  const Eigen::Vector3d cube = cube_of(obs);
  return {cube.x() + testing::state(obs, "cube_to_goal", 0),
          cube.y() + testing::state(obs, "cube_to_goal", 1), ArmPushTask::kTableTop};
}

// A scripted push: hover behind the cube (seen from the goal), descend to the cube's height and
// push along the line to the goal. A finite-difference Jacobian on a private copy of the arm
// tracks the fingertips' position, the hand pointing down, and the line through its two fingers
// along the push (so that the leading finger pushes instead of the cube slipping between them).
class ScriptedPush {
 public:
  ScriptedPush() {
    engine::WorldConfig config;
    config.ground_plane = false;
    world_ = std::make_unique<engine::World>(config);
    const auto model = engine::default_model_cache().load_urdf(engine::asset_path("arm/arm.urdf"));
    engine::RobotOptions options;
    options.X_world_base.translation().z() = ArmPushTask::kBaseHeight;
    robot_ = world_->add_robot(model, options);
    end_effector_ = model->link_index("end_effector");
    hand_ = model->link_index("hand");
  }

  Value operator()(const Value& obs) {
    Eigen::VectorXd q(7);
    for (int d = 0; d < 7; ++d) q[d] = testing::state(obs, "joint_pos", d);
    const Eigen::Vector3d cube = cube_of(obs);
    const Eigen::Vector3d goal = goal_of(obs);
    const Eigen::Vector3d tip = vec3(obs, "end_effector_pos");
    if (!direction_) {
      Eigen::Vector3d d = goal - cube;
      d.z() = 0.0;
      direction_ = d.normalized();
    }
    const Eigen::Vector3d dir = *direction_;
    constexpr double kBehind = 0.10;  // fingertip centre behind the cube centre while pushing
    Eigen::Vector3d target = tip;
    const Eigen::Vector3d start = cube - 0.13 * dir;
    if (phase_ == 0) {  // above the start of the push
      target = Eigen::Vector3d(start.x(), start.y(), cube.z() + 0.10);
      if ((tip - target).norm() < 0.02) phase_ = 1;
    }
    if (phase_ == 1) {  // down to the cube's height
      target = Eigen::Vector3d(start.x(), start.y(), cube.z());
      if ((tip - target).norm() < 0.015) phase_ = 2;
    }
    if (phase_ == 2) {  // push until the cube's centre is at the goal
      target = goal - kBehind * dir;
      target.z() = cube.z();
    }
    Eigen::Vector3d velocity = 3.0 * (target - tip);
    if (velocity.norm() > 0.2) velocity *= 0.2 / velocity.norm();

    const auto outputs = [this](const Eigen::VectorXd& joints) {
      world_->set_joint_state(robot_, joints, Eigen::VectorXd::Zero(7));
      Eigen::Matrix<double, 9, 1> y;
      y.head<3>() = world_->link_pose(robot_, end_effector_).translation();
      y.segment<3>(3) = world_->link_pose(robot_, hand_).linear().col(2);
      y.tail<3>() = world_->link_pose(robot_, hand_).linear().col(1);
      return y;
    };
    const Eigen::Matrix<double, 9, 1> y = outputs(q);
    // The finger line along the push, in whichever sense is nearer.
    const Eigen::Vector3d finger_axis = y.tail<3>().dot(dir) >= 0 ? dir : Eigen::Vector3d(-dir);
    Eigen::Matrix<double, 9, 1> error;
    error.head<3>() = velocity;
    error.segment<3>(3) = 2.0 * (Eigen::Vector3d(0, 0, -1) - y.segment<3>(3));
    error.tail<3>() = 2.0 * (finger_axis - y.tail<3>());
    Eigen::Matrix<double, 9, 7> jacobian;
    for (int d = 0; d < 7; ++d) {
      Eigen::VectorXd moved = q;
      moved[d] += 1e-6;
      jacobian.col(d) = (outputs(moved) - y) / 1e-6;
    }
    const Eigen::Matrix<double, 9, 9> damped =
        jacobian * jacobian.transpose() + 1e-3 * Eigen::Matrix<double, 9, 9>::Identity();
    const Eigen::VectorXd qdot = jacobian.transpose() * damped.ldlt().solve(error);
    std::vector<float> action(7);
    for (int d = 0; d < 7; ++d) {
      action[static_cast<std::size_t>(d)] =
          static_cast<float>(std::clamp(qdot[d] / ArmPushTask::kMaxJointSpeed, -1.0, 1.0));
    }
    return Array::from_vector<float>({7}, action);
  }

 private:
  std::unique_ptr<engine::World> world_;
  engine::RobotId robot_;
  int end_effector_ = 0;
  int hand_ = 0;
  int phase_ = 0;
  std::optional<Eigen::Vector3d> direction_;
};

TEST(ArmPushTest, ScriptedPushMovesTheCubeToTheGoal) {
  std::unique_ptr<Env> env = make("ArmPush-v0", {{"obs_mode", "state"}});
  double scripted = 0.0;
  double random = 0.0;
  for (std::uint64_t seed = 0; seed < 3; ++seed) {
    const Value start = env->reset(seed).obs;
    const double initial = (cube_of(start) - goal_of(start)).head<2>().norm();
    ScriptedPush push;
    Value obs = start;
    double total = 0.0;
    for (bool done = false; !done;) {
      const StepResult step = env->step(push(obs));
      total += step.reward;
      obs = step.obs;
      done = step.terminated || step.truncated;
    }
    const double final_distance = (cube_of(obs) - goal_of(obs)).head<2>().norm();
    std::cout << "ArmPush-v0 seed " << seed << ": cube " << initial
              << " m from the goal, after the push " << final_distance << " m; return " << total
              << "\n";
    EXPECT_LT(final_distance, 0.05) << "seed " << seed;
    scripted += total / 3.0;
    random += testing::episode_return(*env, seed, testing::random_policy(*env, seed)) / 3.0;
  }
  std::cout << "ArmPush-v0 mean return over 3 episodes (500 steps): scripted push " << scripted
            << ", random " << random << "\n";
  EXPECT_GT(scripted, random + 100.0);
}

TEST(ArmPushTest, CubeAndGoalDifferAcrossSeedsAndStartApart) {
  std::unique_ptr<Env> env = make("ArmPush-v0", {{"obs_mode", "state"}});
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (std::uint64_t seed = 0; seed < 8; ++seed) {
    const Value obs = env->reset(seed).obs;
    const Eigen::Vector3d cube = cube_of(obs);
    EXPECT_GE((cube - goal_of(obs)).head<2>().norm(), 0.12 - 1e-6);
    EXPECT_NEAR(cube.z(), ArmPushTask::kTableTop + 0.025, 1e-3);
    EXPECT_NE(cube, previous);
    previous = cube;
  }
}

}  // namespace
}  // namespace pixelgym
