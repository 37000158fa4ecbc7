// WalkerStand and WalkerWalk: dm_control's planar walker, rewarded for standing tall (and
// walking forward).
#pragma once

#include <Eigen/Core>
#include <array>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/task.h"

namespace pixelgym {

/// dm_control's walker (suite/walker.py, walker.xml) in Bullet: a torso on two legs of thigh, leg
/// and foot, moving in the x-z plane (assets/walker, made by assets/tools/make_walker.py:
/// dm_control's capsules, masses, joint ranges, damping and motor gears). Actions are the six
/// leg torques, Box(-1, 1, (6,)) in dm_control's order (right hip, knee, ankle, then left) times
/// each joint's gear (hip 100, knee 50, ankle 20 N m).
/// - Reward (dm_control's): stand = (3 standing + upright) / 4, with standing =
///   tolerance(torso height, (1.2, inf), margin 0.6) (gaussian, 0.1 at the margin) and upright =
///   (1 + the torso's z axis's z) / 2. WalkerStand: stand. WalkerWalk: stand (5 move + 1) / 6 with
///   move = tolerance(centre-of-mass x speed, (1, inf), margin 0.5, linear, 0.5 at the margin) =
///   clip(speed, 0, 1).
/// - State: orientations (14: for the torso, then the right and the left thigh, leg and foot, the
///   xx and xz entries of the body's rotation, cos and sin of its pitch), height (the torso's
///   centre, m), joint_pos (8: qpos without rootx, dm_control's order: rootz, rooty, right hip,
///   knee, ankle, left ...), joint_vel (9: every joint's rate in that order, rootx's included;
///   dm_control's "velocity"). dm_control's observation is orientations, height and velocity.
/// - Episodes: the six leg joints start uniform in their ranges and the torso's pitch uniform in
///   [-pi, pi), its centre 1.3 m up: the walker falls from there. 1000 control steps of 0.025 s;
///   no termination.
/// - Cameras: "side" (dm_control's camera 0: 2 m to the side and 1.2 m above the centre of mass,
///   looking 30 degrees down, following it) and "back" (behind it, following it too).
class WalkerTask final : public Task {
 public:
  /// `walk_speed_m_s`: 0 for WalkerStand, 1 for WalkerWalk (dm_control's _WALK_SPEED).
  explicit WalkerTask(double walk_speed_m_s) : walk_speed_(walk_speed_m_s) {}

  std::vector<std::string> camera_names() const override { return {"side", "back"}; }
  SpacePtr action_space() const override;
  std::vector<StateSpec> state_specs() const override {
    return {{"orientations", {14}}, {"height", {1}}, {"joint_pos", {8}}, {"joint_vel", {9}}};
  }
  double control_timestep_s() const override { return 0.025; }
  engine::WorldConfig world_config() const override;

  void build(engine::World& world) override;
  render::Camera camera(const std::string& name, const engine::World& world) const override;
  void initialize_episode(engine::World& world, Rng& rng) override;
  void before_step(const Value& action, engine::World& world) override;
  void observe(const engine::World& world, StateSlots& state) const override;
  double reward(const engine::World& world) const override;

  /// The torso's centre's height, m.
  double torso_height(const engine::World& world) const;
  /// The z component of the torso's z axis: 1 upright, -1 upside down.
  double torso_upright(const engine::World& world) const;
  /// The centre of mass's forward (x) speed, m/s.
  double speed(const engine::World& world) const;

  /// dm_control's _STAND_HEIGHT, m.
  static constexpr double kStandHeight = 1.2;
  /// The registry entries: WalkerStand-v0 and WalkerWalk-v0.
  static std::vector<EnvSpec> specs();

 private:
  double walk_speed_;
  engine::RobotId robot_;
  // dm_control's joint order (rootz, rootx, rooty, right hip, knee, ankle, left ...) -> the
  // model's dof; the links of the torso and the six leg bodies in dm_control's order.
  std::array<int, 9> dof_{};
  std::array<int, 7> link_{};
  Eigen::Matrix<double, 6, 1> gears_ = Eigen::Matrix<double, 6, 1>::Zero();
};

}  // namespace pixelgym
