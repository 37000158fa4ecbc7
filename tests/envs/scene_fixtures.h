// Fixed scenes shared by the golden tests and the render benchmark.
#pragma once

#include <memory>

#include "pixelgym/engine/world.h"
#include "pixelgym/envs/tasks/world_scene.h"

namespace pixelgym::testing {

/// A world and its scene, with the camera the goldens use.
struct FixtureScene {
  std::unique_ptr<engine::World> world;
  std::unique_ptr<WorldScene> view;
  render::Camera camera;
};

/// The cart-pole: cart 0.3 m right of centre, pole tipped 0.4 rad; seen from the front, from a
/// little below the rail so that rail and pole stand against the sky.
inline FixtureScene cartpole_scene(int width, int height) {
  FixtureScene f;
  f.world = std::make_unique<engine::World>();
  const engine::RobotId robot = f.world->add_robot(
      engine::default_model_cache().load_urdf(engine::asset_path("cartpole/cartpole.urdf")));
  f.world->set_joint_state(robot, (Eigen::VectorXd(2) << 0.3, 0.4).finished(),
                           Eigen::VectorXd::Zero(2));
  f.view = std::make_unique<WorldScene>(*f.world);
  f.camera = render::Camera::look_at({0, -4.0F, 0.9F}, {0, 0, 1.3F});
  f.camera.fov_y_deg = 50.0F;
  f.camera.width = width;
  f.camera.height = height;
  return f;
}

/// The 7-DOF arm at a fixed bent pose beside a table with a cube and a target marker on it, seen
/// from the side.
inline FixtureScene arm_scene(int width, int height) {
  FixtureScene f;
  f.world = std::make_unique<engine::World>();
  engine::ModelCache& cache = engine::default_model_cache();
  const engine::RobotId arm =
      f.world->add_robot(cache.load_urdf(engine::asset_path("arm/arm.urdf")));
  engine::RobotOptions table;
  table.X_world_base.translation() = Eigen::Vector3f(0.75F, 0, 0).cast<double>();
  f.world->add_robot(cache.load_urdf(engine::asset_path("objects/table.urdf")), table);
  engine::RobotOptions cube;
  cube.fixed_base = false;
  cube.X_world_base.translation() = Eigen::Vector3d(0.6, 0.15, 0.745);
  f.world->add_robot(cache.load_urdf(engine::asset_path("objects/cube.urdf")), cube);
  engine::RobotOptions target;
  target.X_world_base.translation() = Eigen::Vector3d(0.8, -0.2, 0.75);
  f.world->add_robot(cache.load_urdf(engine::asset_path("objects/target.urdf")), target);
  Eigen::VectorXd q(7);
  q << 0.3, 0.9, 0.0, -1.2, 0.0, 0.9, 0.0;
  f.world->set_joint_state(arm, q, Eigen::VectorXd::Zero(7));
  f.view = std::make_unique<WorldScene>(*f.world);
  f.camera = render::Camera::look_at({0.5F, -2.2F, 1.5F}, {0.45F, 0.0F, 0.65F});
  f.camera.width = width;
  f.camera.height = height;
  return f;
}

}  // namespace pixelgym::testing
