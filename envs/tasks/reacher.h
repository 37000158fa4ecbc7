// ReacherEasy-v0 and ReacherHard-v0: a two-link planar arm reaches a random target.
#pragma once

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/task.h"

namespace pixelgym {

/// Two 0.12 m links turning about z on the ground (assets/reacher); actions are the two joint
/// torques, Box(-1, 1, (2,)) times 0.05 N m. Each episode puts a target (a green marker that
/// nothing touches) at a random place within reach, 0.05 to 0.22 m from the shoulder, and starts
/// the arm at random angles.
/// - Reward 1 while the fingertip is within the target radius (Easy 0.05 m, Hard 0.015 m), else 0.
/// - State: joint_pos (2, rad, wrapped), joint_vel (2), to_target (2, m, target minus fingertip
///   in the ground plane). 1000 control steps of 0.02 s. Cameras: "top" (default), "angled".
class ReacherTask final : public Task {
 public:
  /// `target_radius_m`: the marker's radius and the reward's bound (0.05 Easy, 0.015 Hard).
  explicit ReacherTask(double target_radius_m);

  std::vector<std::string> camera_names() const override { return {"top", "angled"}; }
  SpacePtr action_space() const override;
  std::vector<StateSpec> state_specs() const override {
    return {{"joint_pos", {2}}, {"joint_vel", {2}}, {"to_target", {2}}};
  }
  double control_timestep_s() const override { return 0.02; }
  engine::WorldConfig world_config() const override;

  void build(engine::World& world) override;
  render::Camera camera(const std::string& name, const engine::World& world) const override;
  void initialize_episode(engine::World& world, Rng& rng) override;
  void before_step(const Value& action, engine::World& world) override;
  void observe(const engine::World& world, StateSlots& state) const override;
  double reward(const engine::World& world) const override;

  /// World position of the "fingertip" link frame, m.
  Eigen::Vector3d fingertip(const engine::World& world) const;
  /// World position of the target marker's centre, m.
  Eigen::Vector3d target(const engine::World& world) const;

  /// Each joint's torque at action 1, N m.
  static constexpr double kMaxTorqueNm = 0.05;
  /// The registry entries: ReacherEasy-v0 and ReacherHard-v0.
  static std::vector<EnvSpec> specs();

 private:
  double target_radius_m_;
  engine::RobotId robot_;
  int fingertip_link_ = 0;
  engine::BodyId target_body_;
};

}  // namespace pixelgym
