// BallInCupCatch: dm_control's ball in cup, rewarded while the ball is in the cup.
#pragma once

#include <Eigen/Core>
#include <array>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/task.h"

namespace pixelgym {

/// dm_control's ball_in_cup (suite/ball_in_cup.py, ball_in_cup.xml) in Bullet: a cup (five
/// capsules, a U 0.1 m wide and deep, open at the top) on springs of 20 N/m along x and z, and a
/// ball (radius 25 mm) hanging from the cup's bottom by a string of 0.3 m; neither turns
/// (assets/ball_in_cup, made by assets/tools/make_ball_in_cup.py). Actions are the cup's two
/// motors, Box(-1, 1, (2,)) times 5 N (x, then z).
/// - Reward (dm_control's Catch): 1 while the ball's centre is within 25 mm in x and in z of the
///   point 0.05 m above the cup's bottom, on its centre line (in the cup), else 0.
/// - State: joint_pos (4: cup x, cup z, ball x, ball z; the cup from (0, 0.6), the ball from
///   (0, 0.2), m), joint_vel (4). dm_control's position and velocity.
/// - The string: World::add_string, slack up to 0.3 m from the ball's centre to the cup's bottom
///   (0.108 m below its rim), past that a pull-only spring-damper (1,635 N/m, 14.6 N s/m) that
///   stretches by millimetres, as dm_control's nearly rigid limit (docs/tasks.md).
/// - Episodes: the ball starts at x uniform in [-0.2, 0.2] m and 0.4 to 0.7 m up (drawn again
///   until it touches nothing), the cup at (0, 0.6), all at rest. 1000 control steps of 0.02 s;
///   no termination.
/// - Cameras: "cam0" and "cam1", dm_control's (finger_and_cup_camera).
/// docs/tasks.md lists what differs from dm_control and why.
class BallInCupTask final : public Task {
 public:
  BallInCupTask() = default;

  std::vector<std::string> camera_names() const override { return {"cam0", "cam1"}; }
  SpacePtr action_space() const override;
  std::vector<StateSpec> state_specs() const override {
    return {{"joint_pos", {4}}, {"joint_vel", {4}}};
  }
  double control_timestep_s() const override { return 0.02; }
  engine::WorldConfig world_config() const override;

  void build(engine::World& world) override;
  render::Camera camera(const std::string& name, const engine::World& world) const override;
  void initialize_episode(engine::World& world, Rng& rng) override;
  void before_step(const Value& action, engine::World& world) override;
  void observe(const engine::World& world, StateSlots& state) const override;
  double reward(const engine::World& world) const override;

  /// Whether the ball is in the cup (dm_control's in_target).
  bool in_cup(const engine::World& world) const;
  /// The ball's centre relative to the cup's frame (its rim's centre), x and z, m.
  Eigen::Vector2d ball_in_cup_frame(const engine::World& world) const;

  /// The string's length, m (dm_control's tendon range 0 to 0.3).
  static constexpr double kStringLength = 0.3;
  /// Where the string is tied: the cup's bottom, below the cup's frame, m.
  static constexpr double kStringAnchorZ = -0.108;
  /// The point the ball must be near, above the cup's frame (dm_control's target site), and how
  /// near in x and in z (the target box's half size 0.05 less the ball's radius 0.025), m.
  static constexpr double kTargetZ = -0.05;
  static constexpr double kTargetHalfSize = 0.025;
  /// The registry entry: BallInCupCatch-v0.
  static EnvSpec spec_v0();

 private:
  engine::RobotId robot_;
  std::array<int, 4> dof_{};  // cup x, cup z, ball x, ball z -> the model's dof
  int cup_link_ = 0;
  int ball_link_ = 0;
  double gear_ = 0.0;
};

}  // namespace pixelgym
