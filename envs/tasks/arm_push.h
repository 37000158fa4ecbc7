// ArmPush-v0: the 7-DOF arm pushes a cube across a table to a goal.
#pragma once

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/task.h"

namespace pixelgym {

/// The arm of assets/arm stands on a 0.5 m pedestal beside a table (assets/objects); a 5 cm cube
/// lies on the table and a green marker (never touched) shows the goal, both at random places
/// at least 0.12 m apart. The episode starts with the hand pointing down above the table.
/// - Actions: Box(-1, 1, (7,)) joint velocities times 1.5 rad/s.
/// - Reward: 0.8 x (the cube's distance to the goal in the table plane: 1 within 0.03 m, smooth
///   fall-off to 0.1 at 0.1 m further) + 0.2 x (the end effector's distance to the cube: 1 within
///   0.05 m, the same fall-off), so reaching the cube pays a little and moving it to the goal pays.
/// - State: joint_pos (7), joint_vel (7), end_effector_pos (3), to_cube (3: cube minus end
///   effector), cube_to_goal (2: goal minus cube in the table plane).
///   500 control steps of 0.02 s. Cameras: "fixed" (front-left, default), "top".
class ArmPushTask final : public Task {
 public:
  std::vector<std::string> camera_names() const override { return {"fixed", "top"}; }
  SpacePtr action_space() const override;
  std::vector<StateSpec> state_specs() const override {
    return {{"joint_pos", {7}},
            {"joint_vel", {7}},
            {"end_effector_pos", {3}},
            {"to_cube", {3}},
            {"cube_to_goal", {2}}};
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
  /// World position of the cube's centre, m.
  Eigen::Vector3d cube(const engine::World& world) const;
  /// World position of the goal marker's centre (just above the table top), m.
  Eigen::Vector3d goal(const engine::World& world) const;

  /// Each joint's speed at action 1, rad/s.
  static constexpr double kMaxJointSpeed = 1.5;
  /// Where the arm's base stands (on its pedestal), m above the floor.
  static constexpr double kBaseHeight = 0.5;
  /// Height of the table's top surface, m.
  static constexpr double kTableTop = 0.72;
  /// The registry entry for ArmPush-v0.
  static EnvSpec spec_v0();

 private:
  engine::RobotId arm_;
  engine::RobotId cube_;
  int end_effector_link_ = 0;
  engine::BodyId goal_body_;
};

}  // namespace pixelgym
