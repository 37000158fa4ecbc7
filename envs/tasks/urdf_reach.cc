#include "pixelgym/envs/tasks/urdf_reach.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/tasks/angles.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "pixelgym/envs/tasks/reward.h"

namespace pixelgym {
namespace {

namespace fs = std::filesystem;

constexpr const char* kId = "UrdfReach-v0";
// The reward's bounds as fractions of the reach: for ArmReach-v0's arm (a reach of 1.38 m),
// that task's 0.05 m and 0.3 m.
constexpr double kWithin = 0.05 / 1.38;
constexpr double kMargin = 0.3 / 1.38;

// The URDF's absolute path: `urdf` as given when it names a file, else from the asset folders.
std::string resolve_urdf(const std::string& urdf) {
  std::error_code error;
  if (fs::is_regular_file(urdf, error)) return fs::absolute(urdf).lexically_normal().string();
  try {
    return engine::asset_path(urdf);
  } catch (const engine::UrdfError&) {
    std::string folders;
    for (const std::string& folder : engine::asset_search_path()) {
      folders += (folders.empty() ? "" : ", ") + folder;
    }
    throw std::invalid_argument(std::string(kId) + ": urdf \"" + urdf +
                                "\" is not a file, nor one in the asset folders (" + folders + ")");
  }
}

}  // namespace

UrdfReachTask::UrdfReachTask(const std::string& urdf, const std::string& end_link)
    : urdf_(urdf), end_link_name_(end_link) {}

const UrdfReachTask::Arm& UrdfReachTask::arm() const {
  if (arm_ != nullptr) return *arm_;
  auto loaded = std::make_unique<Arm>();
  loaded->model = engine::default_model_cache().load_urdf(resolve_urdf(urdf_));
  const engine::RobotModel& model = *loaded->model;
  const auto& links = model.links();
  const auto named = std::find_if(links.begin(), links.end(), [&](const engine::LinkModel& link) {
    return link.name == end_link_name_;
  });
  if (named == links.end()) {
    std::string names;
    for (const engine::LinkModel& link : links) names += (names.empty() ? "" : ", ") + link.name;
    throw std::invalid_argument(std::string(kId) + ": the URDF " + model.path() +
                                " has no link \"" + end_link_name_ + "\"; its links: " + names);
  }
  loaded->end_link = static_cast<int>(named - links.begin());
  bool moves = false;
  for (int link = loaded->end_link; links[static_cast<std::size_t>(link)].parent_joint >= 0;) {
    const engine::JointModel& joint =
        model
            .joints()[static_cast<std::size_t>(links[static_cast<std::size_t>(link)].parent_joint)];
    moves = moves || joint.movable();
    link = joint.parent_link;
  }
  if (!moves) {
    throw std::invalid_argument(std::string(kId) + ": link \"" + end_link_name_ + "\" of " +
                                model.path() +
                                " cannot move: no joint between it and the root link moves");
  }
  const auto dof_count = static_cast<int>(model.movable_joints().size());
  loaded->speeds.resize(dof_count);
  for (int d = 0; d < dof_count; ++d) {
    const double limit =
        model
            .joints()[static_cast<std::size_t>(model.movable_joints()[static_cast<std::size_t>(d)])]
            .velocity_limit;
    loaded->speeds[d] = limit > 0.0 ? limit : kDefaultJointSpeed;
  }
  arm_ = std::move(loaded);
  // The reach: the farthest the end link gets from the root over seeded configurations.
  Rng rng(0);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(dof_count);
  double reach = end_link_position(q).norm();
  for (int sample = 0; sample < 512; ++sample) {
    for (int d = 0; d < dof_count; ++d) q[d] = rng.uniform(lower(d), upper(d));
    reach = std::max(reach, end_link_position(q).norm());
  }
  if (!(reach > 1e-3)) {
    arm_.reset();
    throw std::invalid_argument(std::string(kId) + ": link \"" + end_link_name_ + "\" of " +
                                model.path() + " stays at the root link's origin");
  }
  arm_->reach_m = reach;
  return *arm_;
}

double UrdfReachTask::lower(int dof) const {
  const engine::RobotModel& model = *arm().model;
  const engine::JointModel& joint = model.joints()[static_cast<std::size_t>(
      model.movable_joints()[static_cast<std::size_t>(dof)])];
  return joint.has_limits ? joint.lower : -kPi;
}

double UrdfReachTask::upper(int dof) const {
  const engine::RobotModel& model = *arm().model;
  const engine::JointModel& joint = model.joints()[static_cast<std::size_t>(
      model.movable_joints()[static_cast<std::size_t>(dof)])];
  return joint.has_limits ? joint.upper : kPi;
}

Eigen::Vector3d UrdfReachTask::end_link_position(const Eigen::VectorXd& q) const {
  const engine::RobotModel& model = *arm().model;
  const auto& joints = model.joints();
  std::vector<Eigen::Isometry3d> frames(model.links().size(), Eigen::Isometry3d::Identity());
  int dof = 0;
  for (std::size_t j = 0; j < joints.size(); ++j) {
    const engine::JointModel& joint = joints[j];
    Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
    if (joint.movable()) {
      const double position = q[dof++];
      if (joint.type == engine::JointType::kPrismatic) {
        motion.translation() = position * joint.axis;
      } else {
        motion.linear() = Eigen::AngleAxisd(position, joint.axis).toRotationMatrix();
      }
    }
    frames[static_cast<std::size_t>(joint.child_link)] =
        frames[static_cast<std::size_t>(joint.parent_link)] * joint.X_parent_joint * motion;
  }
  return frames[static_cast<std::size_t>(arm().end_link)].translation();
}

SpacePtr UrdfReachTask::action_space() const {
  return std::make_shared<spaces::Box>(-1.0, 1.0, Shape{dofs()});
}

std::vector<StateSpec> UrdfReachTask::state_specs() const {
  return {{"joint_pos", {dofs()}},
          {"joint_vel", {dofs()}},
          {"end_effector_pos", {3}},
          {"target_pos", {3}}};
}

engine::WorldConfig UrdfReachTask::world_config() const {
  engine::WorldConfig config;
  config.timestep_s = 0.005;
  config.solver_iterations = 20;
  return config;
}

void UrdfReachTask::build(engine::World& world) {
  robot_ = world.add_robot(arm().model);
  target_body_ = world.add_body(marker_body("target", 0.03 * reach_m(), {0.2, 0.85, 0.3, 1.0}));
  command_.resize(dofs());
  joints_.resize(dofs());
}

render::Camera UrdfReachTask::camera(const std::string& name,
                                     const engine::World& /*world*/) const {
  const auto r = static_cast<float>(reach_m());
  render::Camera camera = name == "top"
                              ? render::Camera::look_at(r * Eigen::Vector3f(0.39F, 0.0F, 2.67F),
                                                        r * Eigen::Vector3f(0.39F, 0.0F, 0.33F),
                                                        Eigen::Vector3f::UnitX())
                              : render::Camera::look_at(r * Eigen::Vector3f(1.67F, -1.89F, 1.44F),
                                                        r * Eigen::Vector3f(0.28F, 0.0F, 0.5F));
  camera.fov_y_deg = 45.0F;
  return camera;
}

void UrdfReachTask::initialize_episode(engine::World& world, Rng& rng) {
  Eigen::VectorXd q(dofs());
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  for (int attempt = 0; attempt < 100; ++attempt) {
    for (int d = 0; d < dofs(); ++d) q[d] = rng.uniform(lower(d), upper(d));
    target = end_link_position(q);
    if (target.z() >= 0.05) break;
  }
  target.z() = std::max(target.z(), 0.05);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = target;
  world.set_body_pose(target_body_, pose);

  for (int d = 0; d < dofs(); ++d) {
    const double range = upper(d) - lower(d);
    q[d] = std::clamp(std::clamp(0.0, lower(d), upper(d)) + rng.uniform(-0.1, 0.1) * range,
                      lower(d), upper(d));
  }
  world.set_joint_state(robot_, q, Eigen::VectorXd::Zero(dofs()));
  world.set_control_mode(robot_, engine::ControlMode::kVelocity);
}

void UrdfReachTask::before_step(const Value& action, engine::World& world) {
  const Array& a = action.array();
  for (int d = 0; d < dofs(); ++d) command_[d] = a.element_as_double(d) * joint_speeds()[d];
  world.set_joint_commands(robot_, command_);
}

Eigen::Vector3d UrdfReachTask::end_effector(const engine::World& world) const {
  return world.link_pose(robot_, arm().end_link).translation();
}

Eigen::Vector3d UrdfReachTask::target(const engine::World& world) const {
  return world.body_pose(target_body_).translation();
}

void UrdfReachTask::observe(const engine::World& world, StateSlots& state) const {
  world.joint_positions(robot_, joints_);
  state.set("joint_pos", joints_);
  world.joint_velocities(robot_, joints_);
  state.set("joint_vel", joints_);
  state.set("end_effector_pos", end_effector(world));
  state.set("target_pos", target(world));
}

double UrdfReachTask::reward(const engine::World& world) const {
  return reward::tolerance((end_effector(world) - target(world)).norm(), 0.0, kWithin * reach_m(),
                           kMargin * reach_m());
}

EnvSpec UrdfReachTask::spec_v0() {
  return pixel_task_spec(
      kId, "any arm's URDF and end link: the end link reaches a random reachable target",
      [](const Params& kwargs) {
        return std::make_unique<UrdfReachTask>(kwargs.at("urdf").as_string(),
                                               kwargs.at("end_link").as_string());
      },
      {{"urdf", "arm/arm.urdf",
        "the arm's URDF: a path, or one relative to the asset folders (PIXELGYM_ASSET_PATH, then "
        "pixelgym's assets)"},
       {"end_link", "end_effector", "the URDF link that must reach the target"}});
}

}  // namespace pixelgym
