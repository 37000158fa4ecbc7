// CheetahRun: dm_control's planar cheetah, rewarded for running forward.
#pragma once

#include <Eigen/Core>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/task.h"

namespace pixelgym {

/// dm_control's cheetah (suite/cheetah.py, cheetah.xml) in Bullet: a torso with a head and two
/// three-link legs, moving in the x-z plane (assets/cheetah, made by assets/tools/make_cheetah.py:
/// dm_control's capsules, 14 kg, joint ranges, springs, damping and motor gears). Actions are the
/// six leg torques, Box(-1, 1, (6,)) times each joint's gear (back thigh, shin, foot: 120, 90,
/// 60 N m; front: 90, 60, 30).
/// - Reward: the centre of mass's forward speed over 10 m/s, clipped to [0, 1] (dm_control's
///   tolerance(speed, (10, inf), margin 10, linear, value_at_margin 0)).
/// - State: joint_pos (8: the torso's height offset rootz, its pitch rooty, then the six leg
///   angles; dm_control's "position", qpos without rootx), joint_vel (9: every joint's rate,
///   rootx's first; dm_control's "velocity").
/// - Episodes: each leg joint starts uniform in its range, the torso level at 0.7 m, then 200
///   control steps (2 s) run with no torque so that it settles, as dm_control does. 1000 control
///   steps of 0.01 s; no termination.
/// - Cameras: "side" (dm_control's camera 0: from the side, 3 m away, following the centre of
///   mass) and "back" (from behind and to the side, following it too).
/// docs/tasks.md lists what differs from dm_control and why.
class CheetahTask final : public Task {
 public:
  CheetahTask() = default;

  std::vector<std::string> camera_names() const override { return {"side", "back"}; }
  SpacePtr action_space() const override;
  std::vector<StateSpec> state_specs() const override {
    return {{"joint_pos", {8}}, {"joint_vel", {9}}};
  }
  double control_timestep_s() const override { return 0.01; }
  engine::WorldConfig world_config() const override;

  void build(engine::World& world) override;
  render::Camera camera(const std::string& name, const engine::World& world) const override;
  void initialize_episode(engine::World& world, Rng& rng) override;
  void before_step(const Value& action, engine::World& world) override;
  void observe(const engine::World& world, StateSlots& state) const override;
  double reward(const engine::World& world) const override;

  /// The centre of mass's forward (x) speed, m/s (dm_control's torso_subtreelinvel[0]).
  double speed(const engine::World& world) const;

  /// dm_control's _RUN_SPEED, m/s: the speed of reward 1.
  static constexpr double kRunSpeed = 10.0;
  /// Control steps with no torque after the random start (dm_control: 200 physics steps of its
  /// 0.01 s).
  static constexpr int kSettleSteps = 200;
  /// The registry entry: CheetahRun-v0.
  static EnvSpec spec_v0();

 private:
  engine::RobotId robot_;
  Eigen::Matrix<double, 6, 1> gears_ = Eigen::Matrix<double, 6, 1>::Zero();  // leg efforts, N m
};

}  // namespace pixelgym
