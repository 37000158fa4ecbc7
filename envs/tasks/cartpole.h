// CartPoleBalance, CartPoleSwingup and their Discrete variants, -v0 and -v1.
#pragma once

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/task.h"

namespace pixelgym {

/// A pole hinged on a cart that slides on a rail (assets/cartpole). The action pushes the cart:
/// Box(-1, 1, (1,)) times 10 N, or Discrete(3) = {push left, nothing, push right}.
/// - Balance: the pole starts near upright; Swingup: it starts hanging down.
/// - Reward per step in [0, 1] (dm_control's cart-pole): upright * centred * small control *
///   small angular velocity, where upright = (cos(pole angle) + 1) / 2.
/// - State: joint_pos = (cart position m, pole angle rad in [-pi, pi), 0 upright),
///   joint_vel = their rates. 1000 control steps of 0.01 s per episode; no termination.
/// - Versions: -v1 has -v0's physics, rewards and cameras, drawn from
/// assets/cartpole/cartpole_v1.urdf:
///   a pole twice as thick (0.1 m) in dark red instead of pale yellow, and a larger cart. At 64 x
///   64 the -v0 pole is under a pixel wide and only a little brighter than the sky (in grey frames
///   a faint line); the -v1 pole is about 1.7 pixels wide and dark against the sky.
/// - Cameras: "fixed" (front, the whole rail in view; the default), "tracking" (as fixed,
///   following the cart) and "close" (front, fixed, 2.4 m away instead of 4: x in about
///   [-1.1, 1.1] m, so the pole is about 1.7 times as long and wide in the image; the cart can
///   leave the view near the rail's ends).
class CartPoleTask final : public Task {
 public:
  /// `swing_up`: start hanging down (Swingup) rather than near upright (Balance); `discrete`: the
  /// Discrete(3) action space; `version` is the id's: 0 or 1 (the drawing; see above).
  CartPoleTask(bool swing_up, bool discrete, int version);

  std::vector<std::string> camera_names() const override { return {"fixed", "tracking", "close"}; }
  SpacePtr action_space() const override { return action_space_; }
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

  /// The cart's position on the rail, m (0 at the middle).
  double cart_position(const engine::World& world) const;
  /// The pole's angle, rad, wrapped to [-pi, pi); 0 is upright.
  double pole_angle(const engine::World& world) const;
  /// The pole's angular velocity, rad/s.
  double pole_angular_velocity(const engine::World& world) const;
  /// The last force command in [-1, 1] (a Discrete action a gives a - 1); 0 after a reset.
  double control() const { return control_; }

  /// The force on the cart at command 1, N.
  static constexpr double kMaxForceN = 10.0;

  /// The registry entries: CartPoleBalance, CartPoleSwingup, CartPoleBalanceDiscrete and
  /// CartPoleSwingupDiscrete, each -v0 and -v1.
  static std::vector<EnvSpec> specs();

 private:
  bool swing_up_;
  bool discrete_;
  int version_;
  SpacePtr action_space_;
  engine::RobotId robot_;
  double control_ = 0.0;
};

}  // namespace pixelgym
