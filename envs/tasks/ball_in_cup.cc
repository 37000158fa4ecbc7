#include "pixelgym/envs/tasks/ball_in_cup.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "pixelgym/engine/robot_model.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "pixelgym/envs/tasks/start_state.h"
#include "pixelgym/envs/tasks/tracking_camera.h"

namespace pixelgym {

namespace {

constexpr int kDofs = 4;
constexpr const char* kJoints[kDofs] = {"cup_x", "cup_z", "ball_x", "ball_z"};

// The string's spring and damper, stiff enough to stand in for MuJoCo's nearly rigid limit
// (solref 0.02 s, damping ratio 1, impedance 0.95: it cancels 95% of the acceleration that would
// lengthen the string at once, so the hanging ball stretches it by 0.2-0.4 mm): 1,635 N/m gives
// 0.4 mm under the ball's weight. The damper is critical for the pair's reduced mass, 0.0327 kg
// (2 sqrt(1635 x 0.0327) = 14.6 N s/m). Applied explicitly: the spring turns 224 rad/s x 2 ms =
// 0.45 rad a physics step, well inside the step's stability.
constexpr double kStringStiffness = 1635.0;
constexpr double kStringDamping = 14.6;

}  // namespace

SpacePtr BallInCupTask::action_space() const {
  return std::make_shared<spaces::Box>(-1.0, 1.0, Shape{2});
}

engine::WorldConfig BallInCupTask::world_config() const {
  engine::WorldConfig config;
  config.timestep_s = 0.002;  // dm_control's (MuJoCo's default); 10 physics steps per control
  return config;
}

void BallInCupTask::build(engine::World& world) {
  const auto model =
      engine::default_model_cache().load_urdf(engine::asset_path("ball_in_cup/ball_in_cup.urdf"));
  engine::RobotOptions options;
  options.self_collision = true;  // the cup and the ball are one URDF's two chains
  robot_ = world.add_robot(model, options);
  for (int i = 0; i < kDofs; ++i) dof_[static_cast<std::size_t>(i)] = model->dof_index(kJoints[i]);
  cup_link_ = model->link_index("cup");
  ball_link_ = model->link_index("ball");
  // dm_control's ball-cup friction is 1 (MuJoCo's default); Bullet multiplies the two sides', so
  // the cup's 1.25 times the ball's 0.8.
  engine::ContactMaterial cup;
  cup.friction = 1.25;
  world.set_link_contact_material(robot_, cup_link_, cup);
  gear_ = model->joints()[static_cast<std::size_t>(model->joint_index("cup_x"))].effort_limit;
  engine::StringOptions string;
  string.robot_a = robot_;
  string.link_a = ball_link_;
  string.robot_b = robot_;
  string.link_b = cup_link_;
  string.point_b = Eigen::Vector3d(0.0, 0.0, kStringAnchorZ);
  string.max_length_m = kStringLength;
  string.stiffness_n_m = kStringStiffness;
  string.damping_n_s_m = kStringDamping;
  world.add_string(string);
}

render::Camera BallInCupTask::camera(const std::string& name,
                                     const engine::World& /*world*/) const {
  return finger_and_cup_camera(name);
}

void BallInCupTask::initialize_episode(engine::World& world, Rng& rng) {
  Eigen::VectorXd q = Eigen::VectorXd::Zero(kDofs);
  draw_start_without_contacts(world, robot_, q, "BallInCupTask", [&](Eigen::VectorXd& start) {
    start[dof_[2]] = rng.uniform(-0.2, 0.2);
    start[dof_[3]] = rng.uniform(0.2, 0.5);
  });
}

void BallInCupTask::before_step(const Value& action, engine::World& world) {
  const Array& a = action.array();
  Eigen::Matrix<double, kDofs, 1> forces = Eigen::Matrix<double, kDofs, 1>::Zero();
  forces[dof_[0]] = gear_ * a.element_as_double(0);
  forces[dof_[1]] = gear_ * a.element_as_double(1);
  world.set_joint_commands(robot_, forces);
}

Eigen::Vector2d BallInCupTask::ball_in_cup_frame(const engine::World& world) const {
  const Eigen::Vector3d offset = world.link_pose(robot_, ball_link_).translation() -
                                 world.link_pose(robot_, cup_link_).translation();
  return {offset.x(), offset.z()};
}

bool BallInCupTask::in_cup(const engine::World& world) const {
  const Eigen::Vector2d ball = ball_in_cup_frame(world);
  return std::abs(ball.x()) < kTargetHalfSize && std::abs(ball.y() - kTargetZ) < kTargetHalfSize;
}

void BallInCupTask::observe(const engine::World& world, StateSlots& state) const {
  Eigen::Matrix<double, kDofs, 1> q;
  Eigen::Matrix<double, kDofs, 1> qd;
  world.joint_positions(robot_, q);
  world.joint_velocities(robot_, qd);
  Eigen::Matrix<double, kDofs, 1> position;
  Eigen::Matrix<double, kDofs, 1> velocity;
  for (int i = 0; i < kDofs; ++i) {
    position[i] = q[dof_[static_cast<std::size_t>(i)]];
    velocity[i] = qd[dof_[static_cast<std::size_t>(i)]];
  }
  state.set("joint_pos", position);
  state.set("joint_vel", velocity);
}

double BallInCupTask::reward(const engine::World& world) const { return in_cup(world) ? 1.0 : 0.0; }

EnvSpec BallInCupTask::spec_v0() {
  return pixel_task_spec("BallInCupCatch-v0",
                         "dm_control's ball in cup: swing the ball on its string into the cup; "
                         "two cup forces in [-1, 1]",
                         [](const Params&) { return std::make_unique<BallInCupTask>(); });
}

}  // namespace pixelgym
