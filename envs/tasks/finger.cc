#include "pixelgym/envs/tasks/finger.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/engine/robot_model.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/tasks/angles.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "pixelgym/envs/tasks/start_state.h"
#include "pixelgym/envs/tasks/tracking_camera.h"

namespace pixelgym {

namespace {

constexpr int kDofs = 3;

// The touch sensors: ellipsoids in the distal link's frame (dm_control's touchtop and
// touchbottom sites: size 0.025, 0.03, 0.025 at x = +-0.01, z = -0.17).
struct TouchSite {
  Eigen::Vector3d centre;
  Eigen::Vector3d radii;
  bool contains(const Eigen::Vector3d& point) const {
    return ((point - centre).array() / radii.array()).matrix().squaredNorm() <= 1.0;
  }
};
const TouchSite kTouchTop{{0.01, 0.0, -0.17}, {0.025, 0.03, 0.025}};
const TouchSite kTouchBottom{{-0.01, 0.0, -0.17}, {0.025, 0.03, 0.025}};

// The spinner's contact material: friction, N/m, N s/m (see FingerTask::build).
const engine::ContactMaterial kSpinnerMaterial{1.25, 5000.0, 1.0};

}  // namespace

SpacePtr FingerTask::action_space() const {
  return std::make_shared<spaces::Box>(-1.0, 1.0, Shape{2});
}

engine::WorldConfig FingerTask::world_config() const {
  engine::WorldConfig config;
  config.gravity_m_s2 = Eigen::Vector3d::Zero();  // dm_control's finger turns gravity off
  // 20 physics steps of 1 ms per control step (dm_control: 2 of 0.01 s). Bullet applies the
  // joint damping explicitly, which is stable only while timestep x damping x the largest
  // eigenvalue of the inverse mass matrix stays under 2: with the finger straight that eigenvalue
  // is 1 / 0.00166 kg m^2, so 2.5 N m s/rad needs steps under 1.3 ms (at 2.5 ms the finger's
  // joints ran away to Bullet's 100 rad/s cap from some starts).
  config.timestep_s = 0.001;
  return config;
}

void FingerTask::build(engine::World& world) {
  const auto model =
      engine::default_model_cache().load_urdf(engine::asset_path("finger/finger.urdf"));
  engine::RobotOptions options;
  options.self_collision = true;  // the finger and the spinner are one URDF's two chains
  robot_ = world.add_robot(model, options);
  proximal_ = model->dof_index("proximal");
  distal_ = model->dof_index("distal");
  hinge_ = model->dof_index("hinge");
  distal_link_ = model->link_index("distal");
  // dm_control's contacts here are soft (solimp 0 0.9 0.01, solref 0.02 1) with friction 1.
  // Every finger-spinner contact involves the spinner, so its material makes them so: friction
  // 1.25 (Bullet multiplies it by the finger's 0.8) and a spring of 5000 N/m with 1 N s/m per
  // contact point, chosen by replaying the same starts and actions in MuJoCo (docs/tasks.md).
  // With rigid contacts random actions spun the spinner past 15 rad/s in 5 % of episodes against
  // MuJoCo's 34 % (here 30 %), and SAC from the state found the reward from 1 seed in 3.
  world.set_link_contact_material(robot_, model->link_index("spinner"), kSpinnerMaterial);
  // Room for every contact the distal link can have (Bullet keeps at most 4 points per pair of
  // shapes; it can touch the spinner's 3), so that steps allocate nothing.
  contacts_.reserve(32);
  const auto gear = [&](int dof) {
    return model
        ->joints()[static_cast<std::size_t>(model->movable_joints()[static_cast<std::size_t>(dof)])]
        .effort_limit;
  };
  proximal_gear_ = gear(proximal_);
  distal_gear_ = gear(distal_);
}

render::Camera FingerTask::camera(const std::string& name, const engine::World& /*world*/) const {
  return finger_and_cup_camera(name);
}

void FingerTask::initialize_episode(engine::World& world, Rng& rng) {
  const engine::RobotModel& model = world.robot_model(robot_);
  const auto range = [&](int dof) -> const engine::JointModel& {
    return model
        .joints()[static_cast<std::size_t>(model.movable_joints()[static_cast<std::size_t>(dof)])];
  };
  Eigen::VectorXd q = Eigen::VectorXd::Zero(kDofs);
  draw_start_without_contacts(world, robot_, q, "FingerTask", [&](Eigen::VectorXd& start) {
    start[proximal_] = rng.uniform(range(proximal_).lower, range(proximal_).upper);
    start[distal_] = rng.uniform(range(distal_).lower, range(distal_).upper);
    start[hinge_] = rng.uniform(-kPi, kPi);
  });
}

void FingerTask::before_step(const Value& action, engine::World& world) {
  const Array& a = action.array();
  Eigen::Matrix<double, kDofs, 1> torques = Eigen::Matrix<double, kDofs, 1>::Zero();
  torques[proximal_] = proximal_gear_ * a.element_as_double(0);
  torques[distal_] = distal_gear_ * a.element_as_double(1);
  world.set_joint_commands(robot_, torques);
}

double FingerTask::hinge_velocity(const engine::World& world) const {
  return world.joint_velocity(robot_, hinge_);
}

Eigen::Vector2d FingerTask::touch_forces(const engine::World& world) const {
  const Eigen::Isometry3d X_distal_world = world.link_pose(robot_, distal_link_).inverse();
  world.link_contacts(robot_, distal_link_, contacts_);
  Eigen::Vector2d force = Eigen::Vector2d::Zero();
  for (const engine::LinkContact& contact : contacts_) {
    const Eigen::Vector3d point = X_distal_world * contact.position_world_m;
    if (kTouchTop.contains(point)) force[0] += contact.normal_force_n;
    if (kTouchBottom.contains(point)) force[1] += contact.normal_force_n;
  }
  return force;
}

void FingerTask::observe(const engine::World& world, StateSlots& state) const {
  const double angle = world.joint_position(robot_, hinge_);
  state.set("joint_pos",
            {world.joint_position(robot_, proximal_), world.joint_position(robot_, distal_)});
  // The tip turns about -y: at angle a it is at (-r sin a, r cos a) from the hinge.
  state.set("tip_position", {-kSpinnerRadius * std::sin(angle), kSpinnerRadius * std::cos(angle)});
  state.set("joint_vel", {world.joint_velocity(robot_, proximal_),
                          world.joint_velocity(robot_, distal_), hinge_velocity(world)});
  const Eigen::Vector2d touch = touch_forces(world);
  state.set("touch", {std::log1p(touch[0]), std::log1p(touch[1])});
}

double FingerTask::reward(const engine::World& world) const {
  return hinge_velocity(world) <= -kSpinVelocity ? 1.0 : 0.0;
}

EnvSpec FingerTask::spec_v0() {
  return pixel_task_spec("FingerSpin-v0",
                         "dm_control's finger spins a body on a free hinge; two finger torques "
                         "in [-1, 1]",
                         [](const Params&) { return std::make_unique<FingerTask>(); });
}

}  // namespace pixelgym
