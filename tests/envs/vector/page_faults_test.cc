// The envs of a vector env's worker w >= 1 draw with private copy w of libOSMesa
// (render::MesaCopy). Each copy comes with a libc of its own, and its malloc must not map and
// unmap memory on every step: it did (0.45 page faults per cart-pole step in llvmpipe's draws),
// which made the workers' envs 7-10% slower than the calling thread's and held two threads at
// 1.6-1.8x one. Page faults are counted, not timed: the count does not depend on the machine's
// load.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <memory>
#include <string>
#include <vector>

#include "envs/registry.h"
#include "envs/rng.h"
#include "render/mesa_copy.h"

namespace pixelgym {
namespace {

long page_faults_on_this_thread() {
  rusage usage{};
  getrusage(RUSAGE_THREAD, &usage);
  return usage.ru_minflt;
}

// Minor page faults of `steps` steps of `id` drawn with Mesa copy `copy`, after `warmup`
// uncounted ones (heaps grow at first; the same episode throughout, so no reset is counted).
long page_faults_stepping(const std::string& id, int copy, int warmup, int steps) {
  const render::MesaCopy::Use use(copy);
  std::unique_ptr<Env> env = make(id);
  Rng rng(3);
  std::vector<Value> actions;
  for (int k = 0; k < 64; ++k) actions.push_back(env->action_space().sample(rng));
  ResetResult reset;
  StepResult step;
  reset.obs = env->observation_space().zeros();
  step.obs = env->observation_space().zeros();
  env->reset_into(reset, 0);
  long before = 0;
  for (int t = 0; t < warmup + steps; ++t) {
    if (t == warmup) before = page_faults_on_this_thread();
    env->step_into(actions[static_cast<std::size_t>(t) % actions.size()], step);
    if (step.terminated || step.truncated) env->reset_into(reset);
  }
  return page_faults_on_this_thread() - before;
}

TEST(MesaCopyPageFaults, APrivateCopyStepsWithoutPageFaultsPerStep) {
  constexpr int kWarmup = 2000;
  constexpr int kSteps = 400;
  for (const std::string id : {"CartPoleSwingup-v0", "ArmReach-v0"}) {
    const long linked = page_faults_stepping(id, 0, kWarmup, kSteps);
    const long copy = page_faults_stepping(id, 1, kWarmup, kSteps);
    ASSERT_TRUE(render::MesaCopy::loaded(1)) << render::MesaCopy::why_not(1);
    EXPECT_LE(copy, linked + kSteps / 40) << id << ": page faults in " << kSteps
                                          << " steps: copy 1 " << copy << ", copy 0 " << linked;
  }
}

}  // namespace
}  // namespace pixelgym
