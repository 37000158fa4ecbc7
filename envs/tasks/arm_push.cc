#include "pixelgym/envs/tasks/arm_push.h"

#include <cmath>

#include "pixelgym/engine/robot_model.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "pixelgym/envs/tasks/reward.h"

namespace pixelgym {
namespace {

// The hand points straight down with its fingertips at (0.42, 0, 0.92) in this pose.
const Eigen::Matrix<double, 7, 1> kReadyPose =
    (Eigen::Matrix<double, 7, 1>() << 0.0, 0.106, 0.0, 1.617, 0.0, 1.419, 0.0).finished();
constexpr double kCubeHalf = 0.025;

}  // namespace

SpacePtr ArmPushTask::action_space() const {
  return std::make_shared<spaces::Box>(-1.0, 1.0, Shape{7});
}

engine::WorldConfig ArmPushTask::world_config() const {
  engine::WorldConfig config;
  config.timestep_s = 0.005;
  config.solver_iterations = 20;
  return config;
}

void ArmPushTask::build(engine::World& world) {
  engine::ModelCache& cache = engine::default_model_cache();
  engine::BodyOptions pedestal;
  pedestal.name = "pedestal";
  pedestal.geometry.type = engine::GeometryType::kBox;
  pedestal.geometry.box_size_m = {0.3, 0.3, kBaseHeight};
  pedestal.material.rgba = {0.3, 0.3, 0.33, 1.0};
  pedestal.material.has_rgba = true;
  pedestal.mass_kg = 0.0;
  pedestal.X_world_body.translation() = Eigen::Vector3d(0.0, 0.0, kBaseHeight / 2);
  world.add_body(pedestal);
  const auto arm = cache.load_urdf(engine::asset_path("arm/arm.urdf"));
  engine::RobotOptions arm_options;
  arm_options.X_world_base.translation() = Eigen::Vector3d(0.0, 0.0, kBaseHeight);
  arm_ = world.add_robot(arm, arm_options);
  end_effector_link_ = arm->link_index("end_effector");
  engine::RobotOptions table;
  table.X_world_base.translation() = Eigen::Vector3d(0.75, 0.0, 0.0);
  world.add_robot(cache.load_urdf(engine::asset_path("objects/table.urdf")), table);
  engine::RobotOptions cube_options;
  cube_options.fixed_base = false;
  cube_options.X_world_base.translation() = Eigen::Vector3d(0.5, 0.0, kTableTop + kCubeHalf);
  cube_ = world.add_robot(cache.load_urdf(engine::asset_path("objects/cube.urdf")), cube_options);
  goal_body_ = world.add_body(marker_body("goal", 0.025, {0.2, 0.85, 0.3, 1.0}));
}

render::Camera ArmPushTask::camera(const std::string& name, const engine::World& /*world*/) const {
  render::Camera camera = name == "top"
                              ? render::Camera::look_at({0.55F, 0.0F, 2.3F}, {0.55F, 0.0F, 0.72F},
                                                        Eigen::Vector3f::UnitX())
                              : render::Camera::look_at({1.4F, -1.3F, 1.6F}, {0.45F, 0.0F, 0.8F});
  camera.fov_y_deg = 45.0F;
  return camera;
}

void ArmPushTask::initialize_episode(engine::World& world, Rng& rng) {
  Eigen::VectorXd q = kReadyPose;
  for (int d = 0; d < 7; ++d) q[d] += rng.uniform(-0.05, 0.05);
  world.set_joint_state(arm_, q, Eigen::VectorXd::Zero(7));
  world.set_control_mode(arm_, engine::ControlMode::kVelocity);
  Eigen::Vector2d cube_xy(rng.uniform(0.45, 0.6), rng.uniform(-0.15, 0.15));
  Eigen::Vector2d goal_xy;
  do {
    goal_xy = Eigen::Vector2d(rng.uniform(0.4, 0.65), rng.uniform(-0.2, 0.2));
  } while ((goal_xy - cube_xy).norm() < 0.12);
  // The cube is a floating-base robot: its state is the base pose, set through its world pose.
  Eigen::Isometry3d cube_pose = Eigen::Isometry3d::Identity();
  cube_pose.translation() = Eigen::Vector3d(cube_xy.x(), cube_xy.y(), kTableTop + kCubeHalf);
  world.set_base_pose(cube_, cube_pose);
  Eigen::Isometry3d goal_pose = Eigen::Isometry3d::Identity();
  goal_pose.translation() = Eigen::Vector3d(goal_xy.x(), goal_xy.y(), kTableTop + 0.002);
  world.set_body_pose(goal_body_, goal_pose);
}

void ArmPushTask::before_step(const Value& action, engine::World& world) {
  const Array& a = action.array();
  Eigen::Matrix<double, 7, 1> velocity;
  for (int d = 0; d < 7; ++d) velocity[d] = kMaxJointSpeed * a.element_as_double(d);
  world.set_joint_commands(arm_, velocity);
}

Eigen::Vector3d ArmPushTask::end_effector(const engine::World& world) const {
  return world.link_pose(arm_, end_effector_link_).translation();
}

Eigen::Vector3d ArmPushTask::cube(const engine::World& world) const {
  return world.base_pose(cube_).translation();
}

Eigen::Vector3d ArmPushTask::goal(const engine::World& world) const {
  return world.body_pose(goal_body_).translation();
}

void ArmPushTask::observe(const engine::World& world, StateSlots& state) const {
  const Eigen::Vector3d hand = end_effector(world);
  const Eigen::Vector3d c = cube(world);
  Eigen::Matrix<double, 7, 1> joints;
  world.joint_positions(arm_, joints);
  state.set("joint_pos", joints);
  world.joint_velocities(arm_, joints);
  state.set("joint_vel", joints);
  state.set("end_effector_pos", hand);
  state.set("to_cube", c - hand);
  state.set("cube_to_goal", (goal(world) - c).head<2>());
}

double ArmPushTask::reward(const engine::World& world) const {
  const Eigen::Vector3d c = cube(world);
  const double to_goal = (c - goal(world)).head<2>().norm();
  const double to_cube = (end_effector(world) - c).norm();
  return 0.8 * reward::tolerance(to_goal, 0.0, 0.03, 0.1) +
         0.2 * reward::tolerance(to_cube, 0.0, 0.05, 0.1);
}

EnvSpec ArmPushTask::spec_v0() {
  return pixel_task_spec(
      "ArmPush-v0",
      "7-DOF arm pushes a cube across a table to a goal; 7 joint velocities in [-1, 1]",
      [](const Params&) { return std::make_unique<ArmPushTask>(); });
}

}  // namespace pixelgym
