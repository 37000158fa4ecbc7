#include "pixelgym/envs/tasks/reacher.h"

#include <cmath>

#include "pixelgym/engine/robot_model.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/tasks/angles.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "pixelgym/envs/tasks/reward.h"

namespace pixelgym {

namespace {
// dm_control's wrist range, +-160 degrees (-v1's URDF limit).
constexpr double kWristRangeV1Rad = 160.0 * kPi / 180.0;
}  // namespace

ReacherTask::ReacherTask(double target_radius_m, int version)
    : target_radius_m_(target_radius_m), version_(version) {}

SpacePtr ReacherTask::action_space() const {
  return std::make_shared<spaces::Box>(-1.0, 1.0, Shape{2});
}

engine::WorldConfig ReacherTask::world_config() const {
  engine::WorldConfig config;
  config.timestep_s = 0.005;
  return config;
}

void ReacherTask::build(engine::World& world) {
  const auto model = engine::default_model_cache().load_urdf(
      engine::asset_path(version_ == 0 ? "reacher/reacher.urdf" : "reacher/reacher_v1.urdf"));
  robot_ = world.add_robot(model);
  fingertip_link_ = model->link_index("fingertip");
  target_body_ = world.add_body(marker_body("target", target_radius_m_, {0.2, 0.8, 0.3, 1.0}));
}

render::Camera ReacherTask::camera(const std::string& name, const engine::World& /*world*/) const {
  render::Camera camera = name == "angled"
                              ? render::Camera::look_at({0.0F, -0.55F, 0.45F}, {0.0F, 0.0F, 0.0F})
                              : render::Camera::look_at({0.0F, 0.0F, 0.75F}, {0.0F, 0.0F, 0.0F},
                                                        Eigen::Vector3f::UnitY());
  camera.fov_y_deg = 45.0F;
  return camera;
}

void ReacherTask::initialize_episode(engine::World& world, Rng& rng) {
  Eigen::VectorXd q(2);
  const double wrist_range = version_ == 0 ? 2.5 : kWristRangeV1Rad;
  q << rng.uniform(-kPi, kPi), rng.uniform(-wrist_range, wrist_range);
  world.set_joint_state(robot_, q, Eigen::VectorXd::Zero(2));
  const double angle = rng.uniform(-kPi, kPi);
  const double radius = rng.uniform(0.05, version_ == 0 ? 0.22 : 0.20);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(radius * std::cos(angle), radius * std::sin(angle), 0.02);
  world.set_body_pose(target_body_, pose);
}

void ReacherTask::before_step(const Value& action, engine::World& world) {
  const Array& a = action.array();
  world.set_joint_commands(robot_, Eigen::Vector2d(kMaxTorqueNm * a.element_as_double(0),
                                                   kMaxTorqueNm * a.element_as_double(1)));
}

Eigen::Vector3d ReacherTask::fingertip(const engine::World& world) const {
  return world.link_pose(robot_, fingertip_link_).translation();
}

Eigen::Vector3d ReacherTask::target(const engine::World& world) const {
  return world.body_pose(target_body_).translation();
}

void ReacherTask::observe(const engine::World& world, StateSlots& state) const {
  state.set("joint_pos", {wrap_angle(world.joint_position(robot_, 0)),
                          wrap_angle(world.joint_position(robot_, 1))});
  state.set("joint_vel", {world.joint_velocity(robot_, 0), world.joint_velocity(robot_, 1)});
  state.set("to_target", (target(world) - fingertip(world)).head<2>());
}

double ReacherTask::reward(const engine::World& world) const {
  const Eigen::Vector3d d = target(world) - fingertip(world);
  return reward::tolerance(d.head<2>().norm(), 0.0, reward_radius_m());
}

std::vector<EnvSpec> ReacherTask::specs() {
  std::vector<EnvSpec> specs;
  for (const int version : {0, 1}) {
    for (const auto& [name, radius] : {std::pair<const char*, double>{"ReacherEasy", 0.05},
                                       std::pair<const char*, double>{"ReacherHard", 0.015}}) {
      const double target_radius = radius;
      specs.push_back(pixel_task_spec(
          std::string(name) + "-v" + std::to_string(version),
          std::string("two-link arm reaches a random ") + (radius > 0.02 ? "large" : "small") +
              " target; torques in [-1, 1]" +
              (version == 1 ? "; dm_control's damping, masses and reward radius; a white fingertip"
                            : ""),
          [target_radius, version](const Params&) {
            return std::make_unique<ReacherTask>(target_radius, version);
          }));
    }
  }
  return specs;
}

}  // namespace pixelgym
