#include "pixelgym/envs/tasks/cheetah.h"

#include <cmath>
#include <limits>

#include "pixelgym/engine/robot_model.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "pixelgym/envs/tasks/reward.h"
#include "pixelgym/envs/tasks/tracking_camera.h"

namespace pixelgym {

namespace {

// The cheetah's degrees of freedom: rootx, rootz, rooty, then the legs (the URDF's joint order,
// dm_control's qpos order).
constexpr int kDofs = 9;
constexpr int kFirstLeg = 3;

// Where each camera is relative to the centre of mass (dm_control's trackcom: the camera's
// offset from the centre of mass in the model's drawn pose, where the torso is at (0, 0, 0.7)
// and the centre of mass at (0.0378, 0, 0.551)), and where it looks.
// side: pos (0, -3, 0) in the torso, looking along +y with z up.
const TrackingCamera kSide{{-0.0378F, -3.0F, 0.149F}, {0.0F, 1.0F, 0.0F}, {0.0F, 0.0F, 1.0F}};
// back: pos (-1.8, -1.3, 0.8) in the torso, xyaxes (0.45, -0.9, 0), (0.3, 0.15, 0.94).
const TrackingCamera kBack{
    {-1.8378F, -1.3F, 0.949F}, {0.842F, 0.421F, -0.336F}, {0.301F, 0.150F, 0.942F}};

// Each link's friction: sqrt(0.4), so that two links touching have dm_control's 0.4.
const double kLinkFriction = std::sqrt(0.4);

}  // namespace

SpacePtr CheetahTask::action_space() const {
  return std::make_shared<spaces::Box>(-1.0, 1.0, Shape{6});
}

engine::WorldConfig CheetahTask::world_config() const {
  engine::WorldConfig config;
  // 4 physics steps per control step: the joint springs and damping act explicitly, and on the
  // feet (60 and 120 N m/rad on a joint inertia of about 0.1 kg m^2) need steps this short.
  config.timestep_s = 0.0025;
  // dm_control's friction is 1 with the ground (MuJoCo takes the larger of the ground's 1 and the
  // cheetah's 0.4) and 0.4 between the cheetah's own bodies. Bullet multiplies the two sides', so
  // each link gets sqrt(0.4) (build) and the ground 1 / sqrt(0.4).
  config.ground_friction = 1.0 / kLinkFriction;
  return config;
}

void CheetahTask::build(engine::World& world) {
  const auto model =
      engine::default_model_cache().load_urdf(engine::asset_path("cheetah/cheetah.urdf"));
  engine::RobotOptions options;
  options.self_collision = true;  // as dm_control's cheetah: a foot can hit the torso
  robot_ = world.add_robot(model, options);
  engine::ContactMaterial material;
  material.friction = kLinkFriction;
  for (int link = 0; link < static_cast<int>(model->links().size()); ++link) {
    world.set_link_contact_material(robot_, link, material);
  }
  const auto& joints = model->joints();
  for (int leg = 0; leg < 6; ++leg) {
    gears_[leg] =
        joints[static_cast<std::size_t>(model->movable_joints()[kFirstLeg + leg])].effort_limit;
  }
}

render::Camera CheetahTask::camera(const std::string& name, const engine::World& world) const {
  return (name == "back" ? kBack : kSide).at(world, robot_);
}

void CheetahTask::initialize_episode(engine::World& world, Rng& rng) {
  const engine::RobotModel& model = world.robot_model(robot_);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(kDofs);
  for (int dof = kFirstLeg; dof < kDofs; ++dof) {
    const engine::JointModel& joint =
        model.joints()[static_cast<std::size_t>(model.movable_joints()[dof])];
    q[dof] = rng.uniform(joint.lower, joint.upper);
  }
  world.set_joint_state(robot_, q, Eigen::VectorXd::Zero(kDofs));
  const int substeps =
      static_cast<int>(std::lround(control_timestep_s() / world.config().timestep_s));
  world.step(kSettleSteps * substeps);
}

void CheetahTask::before_step(const Value& action, engine::World& world) {
  const Array& a = action.array();
  Eigen::Matrix<double, kDofs, 1> torques = Eigen::Matrix<double, kDofs, 1>::Zero();
  for (int leg = 0; leg < 6; ++leg) {
    torques[kFirstLeg + leg] = gears_[leg] * a.element_as_double(leg);
  }
  world.set_joint_commands(robot_, torques);
}

double CheetahTask::speed(const engine::World& world) const {
  return world.center_of_mass_velocity(robot_).x();
}

void CheetahTask::observe(const engine::World& world, StateSlots& state) const {
  Eigen::Matrix<double, kDofs, 1> q;
  Eigen::Matrix<double, kDofs, 1> qd;
  world.joint_positions(robot_, q);
  world.joint_velocities(robot_, qd);
  state.set("joint_pos", q.tail<kDofs - 1>());
  state.set("joint_vel", qd);
}

double CheetahTask::reward(const engine::World& world) const {
  return reward::tolerance(speed(world), kRunSpeed, std::numeric_limits<double>::infinity(),
                           kRunSpeed, reward::Sigmoid::kLinear, 0.0);
}

EnvSpec CheetahTask::spec_v0() {
  return pixel_task_spec("CheetahRun-v0",
                         "dm_control's planar cheetah runs forward; six leg torques in [-1, 1]",
                         [](const Params&) { return std::make_unique<CheetahTask>(); });
}

}  // namespace pixelgym
