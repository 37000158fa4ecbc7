// ArmReach-v0: the 7-DOF mesh arm brings its end effector to a random target.
#pragma once

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/task.h"

namespace pixelgym {

/// The arm of assets/arm on the floor; a green marker (never touched) shows a random target in
/// its workspace, 0.35 to 0.7 m from the shoulder, in front and above the floor.
/// - Actions: Box(-1, 1, (7,)): joint velocities times 1.5 rad/s (kwarg control="velocity", the
///   default) or joint torques times each joint's effort limit (control="torque").
/// - Reward: the end effector's distance d to the target: 1 within 0.05 m, falling smoothly to
///   0.1 at 0.3 m further.
/// - State: joint_pos (7), joint_vel (7), end_effector_pos (3), target_pos (3), in metres and
///   radians. 500 control steps of 0.02 s. Cameras: "fixed" (front-left, default), "top".
class ArmReachTask final : public Task {
 public:
  /// `torque_control`: actions are joint torques (kwarg control="torque"), else velocities.
  explicit ArmReachTask(bool torque_control);

  std::vector<std::string> camera_names() const override { return {"fixed", "top"}; }
  SpacePtr action_space() const override;
  std::vector<StateSpec> state_specs() const override {
    return {{"joint_pos", {7}}, {"joint_vel", {7}}, {"end_effector_pos", {3}}, {"target_pos", {3}}};
  }
  double control_timestep_s() const override { return 0.02; }
  engine::WorldConfig world_config() const override;
  int episode_length() const override { return 500; }

  void build(engine::World& world) override;
  render::Camera camera(const std::string& name, const engine::World& world) const override;
  void initialize_episode(engine::World& world, Rng& rng) override;
  void before_step(const Value& action, engine::World& world) override;
  void observe(const engine::World& world, StateSlots& state) const override;
  double reward(const engine::World& world) const override;

  /// World position of the arm's "end_effector" link frame, m.
  Eigen::Vector3d end_effector(const engine::World& world) const;
  /// World position of the target marker's centre, m.
  Eigen::Vector3d target(const engine::World& world) const;

  /// Each joint's speed at action 1 under velocity control, rad/s.
  static constexpr double kMaxJointSpeed = 1.5;
  /// The registry entry for ArmReach-v0 (with its "control" kwarg; make throws
  /// std::invalid_argument for a value other than "velocity" or "torque").
  static EnvSpec spec_v0();

 private:
  bool torque_control_;
  engine::RobotId robot_;
  int end_effector_link_ = 0;
  engine::BodyId target_body_;
  Eigen::VectorXd effort_limits_;
};

}  // namespace pixelgym
