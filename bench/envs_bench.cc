// Throughput of the protocol layer: how much a step of a trivial env costs (validation, order
// enforcement, TimeLimit), and GridWorld's render. Run: build/bench/envs_bench
#include <benchmark/benchmark.h>

#include "pixelgym/envs/registry.h"

namespace pixelgym {
namespace {

void BM_GridWorldStep(benchmark::State& state) {
  std::unique_ptr<Env> env = make("GridWorld-v0");
  env->reset(0);
  Rng rng(0);
  for (auto _ : state) {
    const StepResult result = env->step(env->action_space().sample(rng));
    if (result.terminated || result.truncated) env->reset();
    benchmark::DoNotOptimize(result.reward);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_GridWorldStep);

void BM_GridWorldRender(benchmark::State& state) {
  const auto size = static_cast<int>(state.range(0));
  std::unique_ptr<Env> env =
      make("GridWorld-v0", {{"render_width", size}, {"render_height", size}});
  env->reset(0);
  for (auto _ : state) benchmark::DoNotOptimize(env->render());
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_GridWorldRender)->Arg(84)->Arg(256);

}  // namespace
}  // namespace pixelgym

BENCHMARK_MAIN();
