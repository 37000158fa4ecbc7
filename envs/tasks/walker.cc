#include "pixelgym/envs/tasks/walker.h"

#include <cmath>
#include <limits>

#include "pixelgym/engine/robot_model.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/tasks/angles.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "pixelgym/envs/tasks/reward.h"
#include "pixelgym/envs/tasks/tracking_camera.h"

namespace pixelgym {

namespace {

constexpr int kDofs = 9;
constexpr int kFirstLeg = 3;
constexpr const char* kJoints[kDofs] = {"rootz",     "rootx",      "rooty",
                                        "right_hip", "right_knee", "right_ankle",
                                        "left_hip",  "left_knee",  "left_ankle"};
constexpr const char* kBodies[7] = {"torso",      "right_thigh", "right_leg", "right_foot",
                                    "left_thigh", "left_leg",    "left_foot"};

// Where each camera is relative to the centre of mass (dm_control's trackcom: the camera's
// offset from the centre of mass in the model's drawn pose, torso at (0, 0, 1.3), centre of mass
// at (0.0088, 0, 0.7723)), and where it looks.
// side: pos (0, -2, 0.7) in the torso, euler (60, 0, 0): looking along +y, 30 degrees down.
const TrackingCamera kSide{{-0.0088F, -2.0F, 1.2277F}, {0.0F, 0.866F, -0.5F}, {0.0F, 0.5F, 0.866F}};
// back: pos (-2, 0, 0.5) in the torso, xyaxes (0, -1, 0), (1, 0, 3).
const TrackingCamera kBack{
    {-2.0088F, 0.0F, 1.0277F}, {0.9487F, 0.0F, -0.3162F}, {0.3162F, 0.0F, 0.9487F}};

}  // namespace

SpacePtr WalkerTask::action_space() const {
  return std::make_shared<spaces::Box>(-1.0, 1.0, Shape{6});
}

engine::WorldConfig WalkerTask::world_config() const {
  engine::WorldConfig config;
  config.timestep_s = 0.0025;  // dm_control's; 10 physics steps per control step
  // Bullet multiplies the two sides' friction; the links have 0.8, so the ground's 0.875 gives
  // dm_control's 0.7.
  config.ground_friction = 0.875;
  return config;
}

void WalkerTask::build(engine::World& world) {
  const auto model =
      engine::default_model_cache().load_urdf(engine::asset_path("walker/walker.urdf"));
  robot_ = world.add_robot(model);  // no self-collision, as dm_control's walker
  const auto& movable = model->movable_joints();
  for (int i = 0; i < kDofs; ++i) dof_[static_cast<std::size_t>(i)] = model->dof_index(kJoints[i]);
  for (int b = 0; b < 7; ++b) link_[static_cast<std::size_t>(b)] = model->link_index(kBodies[b]);
  for (int leg = 0; leg < 6; ++leg) {
    gears_[leg] = model
                      ->joints()[static_cast<std::size_t>(
                          movable[static_cast<std::size_t>(dof_[kFirstLeg + leg])])]
                      .effort_limit;
  }
}

render::Camera WalkerTask::camera(const std::string& name, const engine::World& world) const {
  return (name == "back" ? kBack : kSide).at(world, robot_);
}

void WalkerTask::initialize_episode(engine::World& world, Rng& rng) {
  const engine::RobotModel& model = world.robot_model(robot_);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(kDofs);
  q[dof_[2]] = rng.uniform(-kPi, kPi);  // rooty, unlimited
  for (int i = kFirstLeg; i < kDofs; ++i) {
    const engine::JointModel& joint = model.joints()[static_cast<std::size_t>(
        model.movable_joints()[static_cast<std::size_t>(dof_[static_cast<std::size_t>(i)])])];
    q[dof_[static_cast<std::size_t>(i)]] = rng.uniform(joint.lower, joint.upper);
  }
  world.set_joint_state(robot_, q, Eigen::VectorXd::Zero(kDofs));
}

void WalkerTask::before_step(const Value& action, engine::World& world) {
  const Array& a = action.array();
  Eigen::Matrix<double, kDofs, 1> torques = Eigen::Matrix<double, kDofs, 1>::Zero();
  for (int leg = 0; leg < 6; ++leg) {
    torques[dof_[static_cast<std::size_t>(kFirstLeg + leg)]] =
        gears_[leg] * a.element_as_double(leg);
  }
  world.set_joint_commands(robot_, torques);
}

double WalkerTask::torso_height(const engine::World& world) const {
  return world.link_pose(robot_, link_[0]).translation().z();
}

double WalkerTask::torso_upright(const engine::World& world) const {
  return world.link_pose(robot_, link_[0]).linear()(2, 2);
}

double WalkerTask::speed(const engine::World& world) const {
  return world.center_of_mass_velocity(robot_).x();
}

void WalkerTask::observe(const engine::World& world, StateSlots& state) const {
  Eigen::Matrix<double, 14, 1> orientations;
  for (int b = 0; b < 7; ++b) {
    const Eigen::Matrix3d rotation =
        world.link_pose(robot_, link_[static_cast<std::size_t>(b)]).linear();
    orientations[2 * b] = rotation(0, 0);
    orientations[2 * b + 1] = rotation(0, 2);
  }
  state.set("orientations", orientations);
  state.set("height", {torso_height(world)});
  Eigen::Matrix<double, kDofs, 1> q;
  Eigen::Matrix<double, kDofs, 1> qd;
  world.joint_positions(robot_, q);
  world.joint_velocities(robot_, qd);
  Eigen::Matrix<double, kDofs - 1, 1> position;
  Eigen::Matrix<double, kDofs, 1> velocity;
  for (int i = 0, k = 0; i < kDofs; ++i) {
    const int d = dof_[static_cast<std::size_t>(i)];
    velocity[i] = qd[d];
    if (i != 1) position[k++] = q[d];  // not rootx
  }
  state.set("joint_pos", position);
  state.set("joint_vel", velocity);
}

double WalkerTask::reward(const engine::World& world) const {
  using reward::Sigmoid;
  using reward::tolerance;
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  const double standing = tolerance(torso_height(world), kStandHeight, kInfinity, kStandHeight / 2);
  const double upright = (1.0 + torso_upright(world)) / 2.0;
  const double stand = (3.0 * standing + upright) / 4.0;
  if (walk_speed_ == 0.0) return stand;
  const double move =
      tolerance(speed(world), walk_speed_, kInfinity, walk_speed_ / 2, Sigmoid::kLinear, 0.5);
  return stand * (5.0 * move + 1.0) / 6.0;
}

std::vector<EnvSpec> WalkerTask::specs() {
  std::vector<EnvSpec> specs;
  specs.push_back(pixel_task_spec(
      "WalkerStand-v0", "dm_control's planar walker stands up tall; six leg torques in [-1, 1]",
      [](const Params&) { return std::make_unique<WalkerTask>(0.0); }));
  specs.push_back(pixel_task_spec(
      "WalkerWalk-v0",
      "dm_control's planar walker walks forward at 1 m/s; six leg torques in [-1, 1]",
      [](const Params&) { return std::make_unique<WalkerTask>(1.0); }));
  return specs;
}

}  // namespace pixelgym
