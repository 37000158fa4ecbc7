// ReacherEasy and ReacherHard, -v0 and -v1: a two-link planar arm reaches a random target.
#pragma once

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/task.h"

namespace pixelgym {

/// Two 0.12 m links turning about z on the ground (assets/reacher); actions are the two joint
/// torques, Box(-1, 1, (2,)) times 0.05 N m. Each episode puts a target (a green marker that
/// nothing touches) at a random place within reach and starts the arm at random angles.
/// - Reward 1 while the fingertip is within the reward radius of the target's centre, else 0.
/// - State: joint_pos (2, rad, wrapped), joint_vel (2), to_target (2, m, target minus fingertip
///   in the ground plane). 1000 control steps of 0.02 s. Cameras: "top" (default), "angled".
/// - Versions. -v0 (assets/reacher/reacher.urdf): undamped joints, 0.05 kg links, the reward
///   radius is the target's (Easy 0.05 m, Hard 0.015 m), targets 0.05 to 0.22 m from the
///   shoulder, the wrist starting within +-2.5 rad. -v1 is dm_control's reacher
///   (suite/reacher.py, reacher.xml) wherever -v0 differed: joints damped with 0.01 N m s/rad and
///   dm_control's masses (assets/reacher/reacher_v1.urdf), the reward radius the target's plus
///   the finger's 0.01 m (Easy 0.06 m, Hard 0.025 m), targets 0.05 to 0.20 m from the shoulder,
///   the wrist starting anywhere in its +-160 degree range. -v1 also draws the fingertip for small
///   grey frames: a white sphere of 0.02 m radius (-v0: red, 0.012 m, the floor's grey level).
///   docs/experiments/dm-control-parity.md compares the two with dm_control line by line;
///   docs/experiments/frame-probe.md measures what the frames show.
class ReacherTask final : public Task {
 public:
  /// `target_radius_m`: the marker's radius (0.05 Easy, 0.015 Hard); `version` is the id's, 0 or
  /// 1 (see above).
  ReacherTask(double target_radius_m, int version);

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

  /// The reward's bound on the fingertip-to-target distance, m: the target radius (-v0), or the
  /// target radius plus dm_control's finger radius, kFingerRadiusM (-v1).
  double reward_radius_m() const {
    return version_ == 0 ? target_radius_m_ : target_radius_m_ + kFingerRadiusM;
  }

  /// Each joint's torque at action 1, N m.
  static constexpr double kMaxTorqueNm = 0.05;
  /// dm_control's finger radius, m, which its reward adds to the target radius (-v1).
  static constexpr double kFingerRadiusM = 0.01;
  /// The registry entries: ReacherEasy and ReacherHard, each -v0 and -v1.
  static std::vector<EnvSpec> specs();

 private:
  double target_radius_m_;
  int version_;
  engine::RobotId robot_;
  int fingertip_link_ = 0;
  engine::BodyId target_body_;
};

}  // namespace pixelgym
