#include "pixelgym/envs/tasks/acrobot.h"

#include "pixelgym/engine/robot_model.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/tasks/angles.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "pixelgym/envs/tasks/reward.h"

namespace pixelgym {

const Eigen::Vector3d AcrobotTask::kTop{0.0, 0.0, 4.2};

SpacePtr AcrobotTask::action_space() const {
  return std::make_shared<spaces::Box>(-1.0, 1.0, Shape{1});
}

engine::WorldConfig AcrobotTask::world_config() const {
  engine::WorldConfig config;
  config.timestep_s = 0.005;
  return config;
}

void AcrobotTask::build(engine::World& world) {
  const auto model =
      engine::default_model_cache().load_urdf(engine::asset_path("acrobot/acrobot.urdf"));
  robot_ = world.add_robot(model);
  lower_arm_ = model->link_index("lower_arm");
}

render::Camera AcrobotTask::camera(const std::string& name, const engine::World& /*world*/) const {
  render::Camera camera = name == "wide"
                              ? render::Camera::look_at({3.0F, -6.5F, 3.0F}, {0.0F, 0.0F, 2.1F})
                              : render::Camera::look_at({0.0F, -5.8F, 2.2F}, {0.0F, 0.0F, 2.2F});
  camera.fov_y_deg = 45.0F;
  return camera;
}

void AcrobotTask::initialize_episode(engine::World& world, Rng& rng) {
  Eigen::VectorXd q(2);
  q << rng.uniform(-kPi, kPi), rng.uniform(-kPi, kPi);
  world.set_joint_state(robot_, q, Eigen::VectorXd::Zero(2));
}

void AcrobotTask::before_step(const Value& action, engine::World& world) {
  world.set_joint_commands(
      robot_, Eigen::Vector2d(0.0, kMaxTorqueNm * action.array().element_as_double(0)));
}

Eigen::Vector3d AcrobotTask::tip(const engine::World& world) const {
  return world.link_pose(robot_, lower_arm_) * Eigen::Vector3d(0.0, 0.0, -1.0);
}

void AcrobotTask::observe(const engine::World& world, StateSlots& state) const {
  state.set("joint_pos", {wrap_angle(world.joint_position(robot_, 0)),
                          wrap_angle(world.joint_position(robot_, 1))});
  state.set("joint_vel", {world.joint_velocity(robot_, 0), world.joint_velocity(robot_, 1)});
}

double AcrobotTask::reward(const engine::World& world) const {
  return reward::tolerance((tip(world) - kTop).norm(), 0.0, 0.2, 1.0);
}

EnvSpec AcrobotTask::spec_v0() {
  return pixel_task_spec("AcrobotSwingup-v0",
                         "swing a two-link arm up with its elbow alone; torque in [-1, 1]",
                         [](const Params&) { return std::make_unique<AcrobotTask>(); });
}

}  // namespace pixelgym
