// PendulumSwingup-v0: swing a torque-limited pendulum up and hold it.
#pragma once

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/task.h"

namespace pixelgym {

/// A 0.5 m rod with a 1 kg bob (assets/pendulum). The action is a hinge torque,
/// Box(-1, 1, (1,)) times 2 N m, less than gravity's 5.1 N m at horizontal: it must swing up.
/// - Starts at a uniformly random angle. Reward 1 while within 30 degrees of upright, else 0
///   (dm_control's pendulum swing-up).
/// - State: joint_pos = (angle from upright, rad, in [-pi, pi)), joint_vel. 1000 control steps
///   of 0.02 s. Cameras: "fixed" (front, default) and "wide".
class PendulumTask final : public Task {
 public:
  std::vector<std::string> camera_names() const override { return {"fixed", "wide"}; }
  SpacePtr action_space() const override;
  std::vector<StateSpec> state_specs() const override {
    return {{"joint_pos", {1}}, {"joint_vel", {1}}};
  }
  double control_timestep_s() const override { return 0.02; }
  engine::WorldConfig world_config() const override;

  void build(engine::World& world) override;
  render::Camera camera(const std::string& name, const engine::World& world) const override;
  void initialize_episode(engine::World& world, Rng& rng) override;
  void before_step(const Value& action, engine::World& world) override;
  void observe(const engine::World& world, StateSlots& state) const override;
  double reward(const engine::World& world) const override;

  /// The rod's angle, rad: 0 upright, in [-pi, pi).
  double angle_from_upright(const engine::World& world) const;
  /// The hinge's angular velocity, rad/s.
  double angular_velocity(const engine::World& world) const;

  /// The hinge torque at action 1, N m.
  static constexpr double kMaxTorqueNm = 2.0;
  /// The registry entry for PendulumSwingup-v0.
  static EnvSpec spec_v0();

 private:
  engine::RobotId robot_;
};

}  // namespace pixelgym
