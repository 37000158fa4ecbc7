// UrdfReach-v0: a pixel reaching task for any arm a URDF describes, named by its file and the
// link that must reach the target.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "pixelgym/engine/robot_model.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/task.h"

namespace pixelgym {

/// The arm of kwarg `urdf` (a path; a relative one is looked for as given, then in the asset
/// folders: the default is "arm/arm.urdf", the arm of ArmReach-v0) with its root link welded to
/// the floor; the link named by kwarg `end_link` (default "end_effector") must reach a green
/// marker (never touched).
/// - Targets: each episode draws a joint configuration uniformly within the joint limits
///   (continuous joints: [-pi, pi]) and puts the target where it would put the end link, so every
///   target can be reached (drawn again, up to 100 times, while it would be less than 0.05 m
///   above the floor; after 100 draws the last is lifted to 0.05 m).
/// - Start: every joint at 0 (or the limit nearest it) plus up to 0.1 of its range at random.
/// - Actions: Box(-1, 1, (dofs,)): joint velocities times each joint's velocity limit (1.5 rad/s
///   or m/s where the URDF sets none).
/// - Reward: the end link's distance d to the target, as a fraction of the arm's reach R (the
///   farthest the end link gets from the root link's origin over 512 drawn configurations): 1
///   while d <= R / 27.6, falling smoothly to 0.1 at R / 4.6 further; for ArmReach-v0's arm
///   (R = 1.38 m) that task's 0.05 m and 0.3 m.
/// - State: joint_pos (dofs), joint_vel (dofs), end_effector_pos (3), target_pos (3). 500 control
///   steps of 0.02 s. Cameras "fixed" (front-left) and "top", framed from R.
/// The URDF is read when the env is made (not when the id is registered). make throws the
/// importer's UrdfError for a URDF it cannot use, and std::invalid_argument for a `urdf` that
/// names no file (as given or in the asset folders), for an `end_link` the URDF lacks (naming its
/// links), and for one that no movable joint moves or that stays at the root link's origin.
class UrdfReachTask final : public Task {
 public:
  /// Keeps the kwargs; reads nothing. The URDF is read on the first call that needs it (the
  /// spaces, the world, the accessors below), which throws as make does.
  UrdfReachTask(const std::string& urdf, const std::string& end_link);

  std::vector<std::string> camera_names() const override { return {"fixed", "top"}; }
  SpacePtr action_space() const override;
  std::vector<StateSpec> state_specs() const override;
  double control_timestep_s() const override { return 0.02; }
  engine::WorldConfig world_config() const override;
  int episode_length() const override { return 500; }

  void build(engine::World& world) override;
  render::Camera camera(const std::string& name, const engine::World& world) const override;
  void initialize_episode(engine::World& world, Rng& rng) override;
  void before_step(const Value& action, engine::World& world) override;
  void observe(const engine::World& world, StateSlots& state) const override;
  double reward(const engine::World& world) const override;

  /// World position of the end link's URDF frame, m.
  Eigen::Vector3d end_effector(const engine::World& world) const;
  /// World position of the target marker's centre, m.
  Eigen::Vector3d target(const engine::World& world) const;
  /// The arm's reach R in metres (see above).
  double reach_m() const { return arm().reach_m; }
  /// Each degree of freedom's speed at action 1 (rad/s or m/s).
  const Eigen::VectorXd& joint_speeds() const { return arm().speeds; }
  /// Where the end link is, in the root link's frame, at joint positions `q` (one per dof).
  Eigen::Vector3d end_link_position(const Eigen::VectorXd& q) const;

  /// The range each degree of freedom's targets and starts are drawn from: its limits, or
  /// [-pi, pi] for a continuous joint. `dof` must be in [0, dofs) (not checked).
  double lower(int dof) const;
  double upper(int dof) const;

  /// A joint's speed at action 1 (rad/s or m/s) when its URDF sets no velocity limit.
  static constexpr double kDefaultJointSpeed = 1.5;
  /// The registry entry for UrdfReach-v0, with its "urdf" and "end_link" kwargs.
  static EnvSpec spec_v0();

 private:
  struct Arm {
    std::shared_ptr<const engine::RobotModel> model;
    int end_link = 0;
    double reach_m = 0.0;
    Eigen::VectorXd speeds;
  };
  // The URDF is read on first use (when make asks for the spaces or builds the world), not when
  // the id is registered.
  const Arm& arm() const;
  int dofs() const { return static_cast<int>(arm().model->movable_joints().size()); }

  std::string urdf_;
  std::string end_link_name_;
  mutable std::unique_ptr<Arm> arm_;
  // Per-step buffers, sized when the world is built: a step allocates nothing.
  Eigen::VectorXd command_;
  mutable Eigen::VectorXd joints_;
  engine::RobotId robot_;
  engine::BodyId target_body_;
};

}  // namespace pixelgym
