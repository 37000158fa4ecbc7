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

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/rng.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "pixelgym/render/context.h"
#include "pixelgym/render/mesa_copy.h"

namespace pixelgym {
namespace {

long page_faults_on_this_thread() {
  rusage usage{};
  getrusage(RUSAGE_THREAD, &usage);
  return usage.ru_minflt;
}

// The fewest minor page faults in any of `windows` stretches of `steps` steps of `id` drawn with
// Mesa copy `copy`, after `warmup` uncounted ones (heaps grow at first). The faults the bug made
// come on every step, so they are in every stretch; a fault from outside (the kernel reclaiming a
// page while other tests load the machine, say) comes now and then, and the fewest leaves it out.
long fewest_page_faults_stepping(const std::string& id, int copy, int warmup, int steps,
                                 int windows) {
  std::unique_ptr<Env> env = make(id, {{"render_backend", "osmesa"}},
                                  MakeOptions{std::make_shared<PixelRenderResources>(copy, false)});
  Rng rng(3);
  std::vector<Value> actions;
  for (int k = 0; k < 64; ++k) actions.push_back(env->action_space().sample(rng));
  ResetResult reset;
  StepResult step;
  reset.obs = env->observation_space().zeros();
  step.obs = env->observation_space().zeros();
  env->reset_into(reset, 0);
  long fewest = -1;
  long before = 0;
  for (int t = 0; t < warmup + steps * windows; ++t) {
    if (t >= warmup && (t - warmup) % steps == 0) before = page_faults_on_this_thread();
    env->step_into(actions[static_cast<std::size_t>(t) % actions.size()], step);
    if (step.terminated || step.truncated) env->reset_into(reset);
    if (t >= warmup && (t - warmup) % steps == steps - 1) {
      const long faults = page_faults_on_this_thread() - before;
      if (fewest < 0 || faults < fewest) fewest = faults;
    }
  }
  return fewest;
}

TEST(MesaCopyPageFaults, APrivateCopyStepsWithoutPageFaultsPerStep) {
  if (!render::gl_backend_built(render::GlBackend::kOSMesa)) GTEST_SKIP() << "built without OSMesa";
  constexpr int kWarmup = 2000;
  constexpr int kSteps = 400;
  constexpr int kWindows = 3;
  for (const std::string id : {"CartPoleSwingup-v0", "ArmReach-v0"}) {
    const long linked = fewest_page_faults_stepping(id, 0, kWarmup, kSteps, kWindows);
    const long copy = fewest_page_faults_stepping(id, 1, kWarmup, kSteps, kWindows);
    ASSERT_TRUE(render::MesaCopy::loaded(1)) << render::MesaCopy::why_not(1);
    // Without the fix the arm made 257 faults in 400 steps; the bound allows 0.05 a step.
    EXPECT_LE(copy, linked + kSteps / 20)
        << id << ": the fewest page faults in " << kWindows << " stretches of " << kSteps
        << " steps: copy 1 " << copy << ", copy 0 " << linked;
  }
}

}  // namespace
}  // namespace pixelgym
