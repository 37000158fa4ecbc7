#include "pixelgym/envs/tasks/arm_reach.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <iostream>

#include "pixelgym/engine/robot_model.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "tests/envs/tasks/scripted.h"

namespace pixelgym {
namespace {

// Resolved-rate control: joint velocities from the damped pseudo-inverse of the end effector's
// position Jacobian, found by finite differences on a private copy of the arm.
class JacobianController {
 public:
  JacobianController() {
    engine::WorldConfig config;
    config.ground_plane = false;
    world_ = std::make_unique<engine::World>(config);
    const auto model = engine::default_model_cache().load_urdf(engine::asset_path("arm/arm.urdf"));
    robot_ = world_->add_robot(model);
    end_effector_ = model->link_index("end_effector");
  }

  Value operator()(const Value& obs) {
    Eigen::VectorXd q(7);
    for (int d = 0; d < 7; ++d) q[d] = testing::state(obs, "joint_pos", d);
    Eigen::Vector3d target;
    for (int i = 0; i < 3; ++i) target[i] = testing::state(obs, "target_pos", i);
    const Eigen::Vector3d tip = position(q);
    Eigen::Matrix<double, 3, 7> jacobian;
    constexpr double kStep = 1e-5;
    for (int d = 0; d < 7; ++d) {
      Eigen::VectorXd moved = q;
      moved[d] += kStep;
      jacobian.col(d) = (position(moved) - tip) / kStep;
    }
    const Eigen::Vector3d velocity = 3.0 * (target - tip);
    const Eigen::Matrix3d damped =
        jacobian * jacobian.transpose() + 1e-3 * Eigen::Matrix3d::Identity();
    const Eigen::VectorXd qdot = jacobian.transpose() * damped.ldlt().solve(velocity);
    std::vector<float> action(7);
    for (int d = 0; d < 7; ++d) {
      action[static_cast<std::size_t>(d)] =
          static_cast<float>(std::clamp(qdot[d] / ArmReachTask::kMaxJointSpeed, -1.0, 1.0));
    }
    return Array::from_vector<float>({7}, action);
  }

 private:
  Eigen::Vector3d position(const Eigen::VectorXd& q) {
    world_->set_joint_state(robot_, q, Eigen::VectorXd::Zero(7));
    return world_->link_pose(robot_, end_effector_).translation();
  }

  std::unique_ptr<engine::World> world_;
  engine::RobotId robot_;
  int end_effector_ = 0;
};

TEST(ArmReachTest, JacobianControllerReachesTheTarget) {
  std::unique_ptr<Env> env = make("ArmReach-v0", {{"obs_mode", "state"}});
  JacobianController controller;
  double scripted = 0.0;
  double random = 0.0;
  for (std::uint64_t seed = 0; seed < 3; ++seed) {
    scripted +=
        testing::episode_return(*env, seed, [&](const Value& obs) { return controller(obs); }) /
        3.0;
    random += testing::episode_return(*env, seed, testing::random_policy(*env, seed)) / 3.0;
  }
  std::cout << "ArmReach-v0 mean return over 3 episodes (500 steps): Jacobian controller "
            << scripted << ", random " << random << "\n";
  EXPECT_GE(scripted, 400.0);
  EXPECT_GT(scripted, random + 200.0);
}

TEST(ArmReachTest, TargetsDifferAcrossSeedsAndStayAboveTheFloor) {
  std::unique_ptr<Env> env = make("ArmReach-v0", {{"obs_mode", "state"}});
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (std::uint64_t seed = 0; seed < 8; ++seed) {
    const Value obs = env->reset(seed).obs;
    const Eigen::Vector3d target(testing::state(obs, "target_pos", 0),
                                 testing::state(obs, "target_pos", 1),
                                 testing::state(obs, "target_pos", 2));
    EXPECT_GE(target.z(), 0.1 - 1e-6);
    EXPECT_NE(target, previous);
    previous = target;
  }
}

TEST(ArmReachTest, TorqueControlIsAChoice) {
  std::unique_ptr<Env> env = make("ArmReach-v0", {{"obs_mode", "state"}, {"control", "torque"}});
  env->reset(0);
  EXPECT_NO_THROW(env->step(Array::from_vector<float>({7}, std::vector<float>(7, 0.1F))));
  EXPECT_THROW(make("ArmReach-v0", {{"control", "position"}}), std::invalid_argument);
}

}  // namespace
}  // namespace pixelgym
