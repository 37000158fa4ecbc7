// Your own task in one file: CartPoleGoal-v0, a cart-pole that must keep its pole up and bring
// its cart to a goal drawn on the rail, a new position each episode. This file defines the task
// (its world, cameras, actions, observations and reward), registers it, and hands the command
// line to the `pixelgym` tool, so that every subcommand works on it, the trainer included:
//
//   build/examples/own_task/cartpole_goal check CartPoleGoal-v0   # the env checker (check_env)
//   build/examples/own_task/cartpole_goal snapshot CartPoleGoal-v0 --out goal.png
//   build/examples/own_task/cartpole_goal train CartPoleGoal-v0 --minutes 8 --out runs/goal
//
// docs/own-task.md walks through it. A task is a class with the methods of pixelgym::Task
// (envs/tasks/task.h), written like a dm_control suite file; PixelEnv runs it: it steps the
// physics, draws the cameras and builds the observations and spaces.
#include <cmath>
#include <memory>

#include "examples/pixelgym/cli.h"
#include "examples/pixelgym/train_commands.h"
#include "pixelgym/engine/robot_model.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/tasks/angles.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "pixelgym/envs/tasks/reward.h"
#include "pixelgym/envs/tasks/task.h"

namespace {

using pixelgym::engine::World;

class CartPoleGoalTask final : public pixelgym::Task {
 public:
  // Spaces, cameras and timing: known without building a world.
  std::vector<std::string> camera_names() const override { return {"fixed"}; }
  pixelgym::SpacePtr action_space() const override {
    return std::make_shared<pixelgym::spaces::Box>(-1.0, 1.0, pixelgym::Shape{1});  // force / 10 N
  }
  std::vector<pixelgym::StateSpec> state_specs() const override {
    return {{"joint_pos", {2}}, {"joint_vel", {2}}, {"goal", {1}}};
  }
  double control_timestep_s() const override { return 0.01; }
  pixelgym::engine::WorldConfig world_config() const override {
    pixelgym::engine::WorldConfig config;
    config.timestep_s = 0.005;  // two physics steps per control step
    return config;
  }
  int episode_length() const override { return 1000; }

  // The world: the project's cart-pole (assets/cartpole) and a blue ball marking the goal.
  void build(World& world) override {
    robot_ = world.add_robot(pixelgym::engine::default_model_cache().load_urdf(
        pixelgym::engine::asset_path("cartpole/cartpole_v1.urdf")));
    goal_ = world.add_body(pixelgym::marker_body("goal", 0.08, {0.15, 0.35, 0.9, 1.0}));
  }

  pixelgym::render::Camera camera(const std::string& /*name*/,
                                  const World& /*world*/) const override {
    pixelgym::render::Camera camera =
        pixelgym::render::Camera::look_at({0.0F, -4.0F, 0.9F}, {0.0F, 0.0F, 1.3F});
    camera.fov_y_deg = 50.0F;
    return camera;
  }

  // Each episode: the pole near upright, the cart near the middle, the goal anywhere in
  // [-1.2, 1.2] m along the rail (drawn below it, so that the cart never hides it).
  void initialize_episode(World& world, pixelgym::Rng& rng) override {
    Eigen::VectorXd q(2);
    q << rng.uniform(-0.2, 0.2), rng.uniform(-0.05, 0.05);
    world.set_joint_state(robot_, q, Eigen::VectorXd::Zero(2));
    goal_x_ = rng.uniform(-1.2, 1.2);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Vector3d(goal_x_, -0.2, 0.75);
    world.set_body_pose(goal_, pose);
  }

  void before_step(const pixelgym::Value& action, World& world) override {
    world.set_joint_commands(robot_,
                             Eigen::Vector2d(10.0 * action.array().element_as_double(0), 0.0));
  }

  void observe(const World& world, pixelgym::StateSlots& state) const override {
    state.set("joint_pos", {cart(world), pole(world)});
    state.set("joint_vel", {world.joint_velocity(robot_, 0), world.joint_velocity(robot_, 1)});
    state.set("goal", {goal_x_});
  }

  // In [0, 1]: the pole upright, times (1 + how close the cart is to the goal) / 2.
  double reward(const World& world) const override {
    const double upright = (std::cos(pole(world)) + 1.0) / 2.0;
    const double at_goal =
        pixelgym::reward::tolerance(cart(world) - goal_x_, -0.1, 0.1, /*margin=*/1.0);
    return upright * (1.0 + at_goal) / 2.0;
  }

 private:
  double cart(const World& world) const { return world.joint_position(robot_, 0); }
  double pole(const World& world) const {
    return pixelgym::wrap_angle(world.joint_position(robot_, 1));
  }

  pixelgym::engine::RobotId robot_;
  pixelgym::engine::BodyId goal_;
  double goal_x_ = 0.0;
};

}  // namespace

int main(int argc, char** argv) {
  // The id, with the kwargs every pixel task takes (obs_mode, width, height, action_repeat ...).
  pixelgym::register_env(pixelgym::pixel_task_spec(
      "CartPoleGoal-v0", "keep the pole up and bring the cart to a goal on the rail",
      [](const pixelgym::Params&) { return std::make_unique<CartPoleGoalTask>(); }));
  return pixelgym::cli::run_tool(argc, argv, pixelgym::cli::in_process_trainer());
}
