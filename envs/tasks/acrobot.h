// AcrobotSwingup-v0: swing a two-link arm with a passive shoulder up by its elbow.
#pragma once

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/task.h"

namespace pixelgym {

/// Two 1 m, 1 kg links (assets/acrobot); only the elbow is actuated: Box(-1, 1, (1,)) times
/// 2 N m. Starts at uniformly random angles.
/// - Reward: the tip's distance d to the top (4.2 m up, straight above the shoulder):
///   1 within 0.2 m, falling smoothly to 0.1 at 1 m further (dm_control's acrobot, dense).
/// - State: joint_pos = (shoulder, elbow) angles in [-pi, pi) with 0 hanging straight down,
///   joint_vel. 1000 control steps of 0.01 s. Cameras: "fixed" (front, default) and "wide".
class AcrobotTask final : public Task {
 public:
  std::vector<std::string> camera_names() const override { return {"fixed", "wide"}; }
  SpacePtr action_space() const override;
  std::vector<StateSpec> state_specs() const override {
    return {{"joint_pos", {2}}, {"joint_vel", {2}}};
  }
  double control_timestep_s() const override { return 0.01; }
  engine::WorldConfig world_config() const override;

  void build(engine::World& world) override;
  render::Camera camera(const std::string& name, const engine::World& world) const override;
  void initialize_episode(engine::World& world, Rng& rng) override;
  void before_step(const Value& action, engine::World& world) override;
  void observe(const engine::World& world, StateSlots& state) const override;
  double reward(const engine::World& world) const override;

  /// World position of the lower arm's tip.
  Eigen::Vector3d tip(const engine::World& world) const;
  /// The elbow torque at action 1, N m.
  static constexpr double kMaxTorqueNm = 2.0;
  /// The target of the tip: where it is with both links straight up (world, m).
  static const Eigen::Vector3d kTop;

  /// The registry entry for AcrobotSwingup-v0.
  static EnvSpec spec_v0();

 private:
  engine::RobotId robot_;
  int lower_arm_ = 0;
};

}  // namespace pixelgym
