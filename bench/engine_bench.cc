// Physics steps per second for each asset robot (physics only: no rendering, no env).
// Run: build/bench/engine_bench   (items_per_second = physics steps per second, one thread)
#include <benchmark/benchmark.h>

#include <Eigen/Core>

#include "pixelgym/engine/world.h"

namespace pixelgym::engine {
namespace {

// Steps `urdf` under a changing torque (bounded by the URDF's effort limits), as a random policy
// would drive it.
void step_robot(benchmark::State& state, const std::string& urdf, ControlMode mode) {
  World world;
  const RobotId robot = world.add_robot(default_model_cache().load_urdf(asset_path(urdf)));
  world.set_control_mode(robot, mode);
  const int dofs = world.num_dofs(robot);
  Eigen::VectorXd command(dofs);
  std::int64_t t = 0;
  for (auto _ : state) {
    for (int d = 0; d < dofs; ++d) command[d] = 0.5 * std::sin(0.01 * static_cast<double>(t) + d);
    world.set_joint_commands(robot, command);
    world.step();
    ++t;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["dofs"] = dofs;
}

void BM_CartPole(benchmark::State& state) {
  step_robot(state, "cartpole/cartpole.urdf", ControlMode::kTorque);
}
void BM_Pendulum(benchmark::State& state) {
  step_robot(state, "pendulum/pendulum.urdf", ControlMode::kTorque);
}
void BM_Acrobot(benchmark::State& state) {
  step_robot(state, "acrobot/acrobot.urdf", ControlMode::kTorque);
}
void BM_Reacher(benchmark::State& state) {
  step_robot(state, "reacher/reacher.urdf", ControlMode::kTorque);
}
void BM_ArmTorque(benchmark::State& state) {
  step_robot(state, "arm/arm.urdf", ControlMode::kTorque);
}
void BM_ArmPosition(benchmark::State& state) {
  step_robot(state, "arm/arm.urdf", ControlMode::kPosition);
}

// The arm beside a table with a cube on it: contacts included.
void BM_ArmTableCube(benchmark::State& state) {
  World world;
  ModelCache& cache = default_model_cache();
  const RobotId arm = world.add_robot(cache.load_urdf(asset_path("arm/arm.urdf")));
  RobotOptions table;
  table.X_world_base.translation() = Eigen::Vector3d(0.6, 0, 0);
  world.add_robot(cache.load_urdf(asset_path("objects/table.urdf")), table);
  RobotOptions cube;
  cube.fixed_base = false;
  cube.X_world_base.translation() = Eigen::Vector3d(0.5, 0, 0.75);
  world.add_robot(cache.load_urdf(asset_path("objects/cube.urdf")), cube);
  world.set_control_mode(arm, ControlMode::kPosition);
  Eigen::VectorXd target = Eigen::VectorXd::Zero(7);
  std::int64_t t = 0;
  for (auto _ : state) {
    target[1] = 0.5 * std::sin(0.01 * static_cast<double>(t));
    world.set_joint_commands(arm, target);
    world.step();
    ++t;
  }
  state.SetItemsProcessed(state.iterations());
}

BENCHMARK(BM_CartPole);
BENCHMARK(BM_Pendulum);
BENCHMARK(BM_Acrobot);
BENCHMARK(BM_Reacher);
BENCHMARK(BM_ArmTorque);
BENCHMARK(BM_ArmPosition);
BENCHMARK(BM_ArmTableCube);

}  // namespace
}  // namespace pixelgym::engine

BENCHMARK_MAIN();
