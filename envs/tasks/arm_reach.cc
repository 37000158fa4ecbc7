#include "pixelgym/envs/tasks/arm_reach.h"

#include <cmath>

#include "pixelgym/engine/robot_model.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/tasks/angles.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "pixelgym/envs/tasks/reward.h"

namespace pixelgym {
namespace {

// A bent, ready pose the episodes start near.
const Eigen::Matrix<double, 7, 1> kReadyPose =
    (Eigen::Matrix<double, 7, 1>() << 0.0, 0.4, 0.0, -1.4, 0.0, 1.0, 0.0).finished();
const Eigen::Vector3d kShoulder(0.0, 0.0, 0.32);

}  // namespace

ArmReachTask::ArmReachTask(bool torque_control) : torque_control_(torque_control) {}

SpacePtr ArmReachTask::action_space() const {
  return std::make_shared<spaces::Box>(-1.0, 1.0, Shape{7});
}

engine::WorldConfig ArmReachTask::world_config() const {
  engine::WorldConfig config;
  config.timestep_s = 0.005;
  config.solver_iterations = 20;
  return config;
}

void ArmReachTask::build(engine::World& world) {
  const auto model = engine::default_model_cache().load_urdf(engine::asset_path("arm/arm.urdf"));
  robot_ = world.add_robot(model);
  end_effector_link_ = model->link_index("end_effector");
  effort_limits_.resize(7);
  for (int d = 0; d < 7; ++d) {
    effort_limits_[d] = model
                            ->joints()[static_cast<std::size_t>(
                                model->movable_joints()[static_cast<std::size_t>(d)])]
                            .effort_limit;
  }
  target_body_ = world.add_body(marker_body("target", 0.04, {0.2, 0.85, 0.3, 1.0}));
}

render::Camera ArmReachTask::camera(const std::string& name, const engine::World& /*world*/) const {
  render::Camera camera = name == "top"
                              ? render::Camera::look_at({0.35F, 0.0F, 2.4F}, {0.35F, 0.0F, 0.3F},
                                                        Eigen::Vector3f::UnitX())
                              : render::Camera::look_at({1.5F, -1.7F, 1.3F}, {0.25F, 0.0F, 0.45F});
  camera.fov_y_deg = 45.0F;
  return camera;
}

void ArmReachTask::initialize_episode(engine::World& world, Rng& rng) {
  Eigen::VectorXd q = kReadyPose;
  for (int d = 0; d < 7; ++d) q[d] += rng.uniform(-0.15, 0.15);
  world.set_joint_state(robot_, q, Eigen::VectorXd::Zero(7));
  world.set_control_mode(
      robot_, torque_control_ ? engine::ControlMode::kTorque : engine::ControlMode::kVelocity);
  // Gravity is compensated by the velocity motors; torque control gets the raw dynamics.
  const double radius = rng.uniform(0.35, 0.7);
  const double azimuth = rng.uniform(-1.2, 1.2);
  const double elevation = rng.uniform(-0.35, 0.6);
  Eigen::Vector3d target =
      kShoulder + radius * Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                                           std::cos(elevation) * std::sin(azimuth),
                                           std::sin(elevation));
  target.z() = std::max(target.z(), 0.1);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = target;
  world.set_body_pose(target_body_, pose);
}

void ArmReachTask::before_step(const Value& action, engine::World& world) {
  const Array& a = action.array();
  Eigen::Matrix<double, 7, 1> command;
  for (int d = 0; d < 7; ++d) {
    const double u = a.element_as_double(d);
    command[d] = torque_control_ ? u * effort_limits_[d] : u * kMaxJointSpeed;
  }
  world.set_joint_commands(robot_, command);
}

Eigen::Vector3d ArmReachTask::end_effector(const engine::World& world) const {
  return world.link_pose(robot_, end_effector_link_).translation();
}

Eigen::Vector3d ArmReachTask::target(const engine::World& world) const {
  return world.body_pose(target_body_).translation();
}

void ArmReachTask::observe(const engine::World& world, StateSlots& state) const {
  Eigen::Matrix<double, 7, 1> joints;
  world.joint_positions(robot_, joints);
  state.set("joint_pos", joints);
  world.joint_velocities(robot_, joints);
  state.set("joint_vel", joints);
  state.set("end_effector_pos", end_effector(world));
  state.set("target_pos", target(world));
}

double ArmReachTask::reward(const engine::World& world) const {
  return reward::tolerance((end_effector(world) - target(world)).norm(), 0.0, 0.05, 0.3);
}

EnvSpec ArmReachTask::spec_v0() {
  return pixel_task_spec(
      "ArmReach-v0",
      "7-DOF mesh arm brings its end effector to a random target; 7 joint velocities in [-1, 1]",
      [](const Params& kwargs) {
        const std::string control = kwargs.at("control").as_string();
        if (control != "velocity" && control != "torque") {
          throw std::invalid_argument(
              "ArmReach-v0: control must be \"velocity\" or \"torque\", got \"" + control + "\"");
        }
        return std::make_unique<ArmReachTask>(control == "torque");
      },
      {{"control", "velocity", "\"velocity\" (joint velocities) or \"torque\" (joint torques)"}});
}

}  // namespace pixelgym
