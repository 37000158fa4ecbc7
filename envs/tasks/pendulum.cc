#include "pixelgym/envs/tasks/pendulum.h"

#include <cmath>

#include "pixelgym/engine/robot_model.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/tasks/angles.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "pixelgym/envs/tasks/reward.h"

namespace pixelgym {

SpacePtr PendulumTask::action_space() const {
  return std::make_shared<spaces::Box>(-1.0, 1.0, Shape{1});
}

engine::WorldConfig PendulumTask::world_config() const {
  engine::WorldConfig config;
  config.timestep_s = 0.005;
  return config;
}

void PendulumTask::build(engine::World& world) {
  robot_ = world.add_robot(
      engine::default_model_cache().load_urdf(engine::asset_path("pendulum/pendulum.urdf")));
}

render::Camera PendulumTask::camera(const std::string& name, const engine::World& /*world*/) const {
  render::Camera camera = name == "wide"
                              ? render::Camera::look_at({1.2F, -3.2F, 1.6F}, {0.0F, 0.0F, 1.0F})
                              : render::Camera::look_at({0.0F, -2.2F, 1.2F}, {0.0F, 0.0F, 1.15F});
  camera.fov_y_deg = 45.0F;
  return camera;
}

void PendulumTask::initialize_episode(engine::World& world, Rng& rng) {
  world.set_joint_state(robot_, Eigen::VectorXd::Constant(1, rng.uniform(-kPi, kPi)),
                        Eigen::VectorXd::Zero(1));
}

void PendulumTask::before_step(const Value& action, engine::World& world) {
  world.set_joint_commands(
      robot_, Eigen::Matrix<double, 1, 1>(kMaxTorqueNm * action.array().element_as_double(0)));
}

double PendulumTask::angle_from_upright(const engine::World& world) const {
  return wrap_angle(world.joint_position(robot_, 0) - kPi);
}

double PendulumTask::angular_velocity(const engine::World& world) const {
  return world.joint_velocity(robot_, 0);
}

void PendulumTask::observe(const engine::World& world, StateSlots& state) const {
  state.set("joint_pos", {angle_from_upright(world)});
  state.set("joint_vel", {angular_velocity(world)});
}

double PendulumTask::reward(const engine::World& world) const {
  return reward::tolerance(std::cos(angle_from_upright(world)), std::cos(kPi / 6.0), 1.0);
}

EnvSpec PendulumTask::spec_v0() {
  return pixel_task_spec("PendulumSwingup-v0",
                         "swing a torque-limited pendulum up and hold it; torque in [-1, 1]",
                         [](const Params&) { return std::make_unique<PendulumTask>(); });
}

}  // namespace pixelgym
