#include "pixelgym/envs/tasks/cartpole.h"

#include <cmath>

#include "pixelgym/engine/robot_model.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/discrete.h"
#include "pixelgym/envs/tasks/angles.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "pixelgym/envs/tasks/reward.h"

namespace pixelgym {

CartPoleTask::CartPoleTask(bool swing_up, bool discrete, int version)
    : swing_up_(swing_up),
      discrete_(discrete),
      version_(version),
      action_space_(discrete ? SpacePtr(std::make_shared<spaces::Discrete>(3))
                             : SpacePtr(std::make_shared<spaces::Box>(-1.0, 1.0, Shape{1}))) {}

engine::WorldConfig CartPoleTask::world_config() const {
  engine::WorldConfig config;
  config.timestep_s = 0.005;  // two physics steps per control step
  return config;
}

void CartPoleTask::build(engine::World& world) {
  const char* urdf = version_ == 0 ? "cartpole/cartpole.urdf" : "cartpole/cartpole_v1.urdf";
  robot_ = world.add_robot(engine::default_model_cache().load_urdf(engine::asset_path(urdf)));
}

render::Camera CartPoleTask::camera(const std::string& name, const engine::World& world) const {
  if (name == "close") {
    render::Camera camera = render::Camera::look_at({0.0F, -2.4F, 1.2F}, {0.0F, 0.0F, 1.35F});
    camera.fov_y_deg = 50.0F;
    return camera;
  }
  const float x = name == "tracking" ? static_cast<float>(cart_position(world)) : 0.0F;
  render::Camera camera = render::Camera::look_at({x, -4.0F, 0.9F}, {x, 0.0F, 1.3F});
  camera.fov_y_deg = 50.0F;
  return camera;
}

void CartPoleTask::initialize_episode(engine::World& world, Rng& rng) {
  Eigen::VectorXd q(2);
  Eigen::VectorXd qd(2);
  q[0] = rng.uniform(-0.25, 0.25);
  q[1] = swing_up_ ? kPi + rng.uniform(-0.1, 0.1) : rng.uniform(-0.05, 0.05);
  qd[0] = 0.01 * rng.normal();
  qd[1] = 0.01 * rng.normal();
  world.set_joint_state(robot_, q, qd);
  control_ = 0.0;
}

void CartPoleTask::before_step(const Value& action, engine::World& world) {
  const Array& a = action.array();
  control_ = discrete_ ? static_cast<double>(a.element_as_double(0)) - 1.0 : a.element_as_double(0);
  world.set_joint_commands(robot_, Eigen::Vector2d(kMaxForceN * control_, 0.0));
}

double CartPoleTask::cart_position(const engine::World& world) const {
  return world.joint_position(robot_, 0);
}

double CartPoleTask::pole_angle(const engine::World& world) const {
  return wrap_angle(world.joint_position(robot_, 1));
}

double CartPoleTask::pole_angular_velocity(const engine::World& world) const {
  return world.joint_velocity(robot_, 1);
}

void CartPoleTask::observe(const engine::World& world, StateSlots& state) const {
  state.set("joint_pos", {cart_position(world), pole_angle(world)});
  state.set("joint_vel", {world.joint_velocity(robot_, 0), pole_angular_velocity(world)});
}

double CartPoleTask::reward(const engine::World& world) const {
  using reward::Sigmoid;
  using reward::tolerance;
  const double upright = (std::cos(pole_angle(world)) + 1.0) / 2.0;
  const double centred = (1.0 + tolerance(cart_position(world), 0.0, 0.0, 2.0)) / 2.0;
  const double small_control =
      (4.0 + tolerance(control_, 0.0, 0.0, 1.0, Sigmoid::kQuadratic, 0.0)) / 5.0;
  const double small_velocity =
      (1.0 + tolerance(pole_angular_velocity(world), 0.0, 0.0, 5.0)) / 2.0;
  return upright * centred * small_control * small_velocity;
}

std::vector<EnvSpec> CartPoleTask::specs() {
  std::vector<EnvSpec> specs;
  for (const int version : {0, 1}) {
    for (const bool swing_up : {false, true}) {
      for (const bool discrete : {false, true}) {
        const std::string id = std::string("CartPole") + (swing_up ? "Swingup" : "Balance") +
                               (discrete ? "Discrete" : "") + "-v" + std::to_string(version);
        const std::string description =
            std::string(swing_up ? "swing the pole up from hanging and balance it"
                                 : "keep the pole upright") +
            (discrete ? "; Discrete(3) pushes" : "; force in [-1, 1]") +
            (version == 1 ? "; a thicker, dark pole (v0's physics)" : "");
        specs.push_back(
            pixel_task_spec(id, description, [swing_up, discrete, version](const Params&) {
              return std::make_unique<CartPoleTask>(swing_up, discrete, version);
            }));
      }
    }
  }
  return specs;
}

}  // namespace pixelgym
