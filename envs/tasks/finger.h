// FingerSpin: dm_control's finger, rewarded for spinning the free body on its hinge.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "pixelgym/engine/world.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/task.h"

namespace pixelgym {

/// dm_control's finger (suite/finger.py, finger.xml) in Bullet, with no gravity: a two-link
/// finger on a hinge at (-0.2, 0, 0.4) and a spinner (two capsules side by side, 0.13 m from its
/// hinge to either end) on a free hinge at (0.2, 0, 0.4), every hinge turning about -y
/// (assets/finger, made by assets/tools/make_finger.py). Actions are the two finger torques,
/// Box(-1, 1, (2,)) times each joint's gear (proximal 30, distal 15 N m).
/// - Reward (dm_control's Spin): 1 while the spinner's hinge turns at -15 rad/s or faster (its
///   top moving right, as the camera sees it), else 0.
/// - State: joint_pos (2: proximal, distal angles; the proximal is 0 pointing at the spinner and
///   -pi/2 hanging down, as dm_control's with its ref), tip_position (2: the x and z of the
///   spinner's tip, 0.13 m up its capsules from the hinge, relative to the hinge), joint_vel (3:
///   proximal, distal, spinner rates), touch (2: log(1 + the normal force, N) on the fingertip's
///   top and bottom sensor ellipsoids). Together dm_control's position, velocity and touch.
/// - Episodes: the finger's joints start uniform in their ranges (+-110 degrees) and the
///   spinner's angle uniform in [-pi, pi), drawn again until nothing touches; at rest. 1000
///   control steps of 0.02 s; no termination.
/// - Cameras: "cam0" (dm_control's camera 0: 1 m in front, 0.4 m above the hinges, looking 26.6
///   degrees down) and "cam1" (level with them).
/// docs/tasks.md lists what differs from dm_control and why.
class FingerTask final : public Task {
 public:
  FingerTask() = default;

  std::vector<std::string> camera_names() const override { return {"cam0", "cam1"}; }
  SpacePtr action_space() const override;
  std::vector<StateSpec> state_specs() const override {
    return {{"joint_pos", {2}}, {"tip_position", {2}}, {"joint_vel", {3}}, {"touch", {2}}};
  }
  double control_timestep_s() const override { return 0.02; }
  engine::WorldConfig world_config() const override;

  void build(engine::World& world) override;
  render::Camera camera(const std::string& name, const engine::World& world) const override;
  void initialize_episode(engine::World& world, Rng& rng) override;
  void before_step(const Value& action, engine::World& world) override;
  void observe(const engine::World& world, StateSlots& state) const override;
  double reward(const engine::World& world) const override;

  /// The spinner hinge's rate, rad/s, about -y (dm_control's hinge_velocity).
  double hinge_velocity(const engine::World& world) const;
  /// The normal force on the fingertip's top and bottom touch sensors, N (dm_control's touch
  /// sensors before log1p): every contact of the distal link inside each sensor's ellipsoid.
  Eigen::Vector2d touch_forces(const engine::World& world) const;

  /// dm_control's _SPIN_VELOCITY, rad/s.
  static constexpr double kSpinVelocity = 15.0;
  /// From the spinner's hinge to its tip (dm_control's tip site and the capsules' reach), m.
  static constexpr double kSpinnerRadius = 0.13;
  /// The registry entry: FingerSpin-v0.
  static EnvSpec spec_v0();

 private:
  engine::RobotId robot_;
  int proximal_ = 0;  // dofs
  int distal_ = 0;
  int hinge_ = 0;
  int distal_link_ = 0;
  double proximal_gear_ = 0.0;
  double distal_gear_ = 0.0;
  mutable std::vector<engine::LinkContact> contacts_;  // touch_forces' buffer
};

}  // namespace pixelgym
