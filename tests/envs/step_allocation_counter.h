// Allocations of an env's buffer path, step by step: the loop every allocation test of an env or
// a wrapper runs. It includes tests/alloc_counter.h, so the same rule holds: include this header
// in exactly ONE source file of a test executable (and not alloc_counter.h beside it).
#pragma once

#include <cstddef>
#include <vector>

#include "pixelgym/envs/env.h"
#include "tests/alloc_counter.h"

namespace pixelgym::testing {

/// Which steps count_step_allocations counts.
enum class CountedSteps {
  kAll,
  /// Not the steps that end an episode (RecordEpisodeStatistics builds its info there, by design).
  kWithinEpisodes,
};

/// Resets `env` into a buffer of its own (seed 0), then takes `warmup_steps + steps` step_into
/// calls into one caller buffer with actions drawn beforehand from Rng(1), resetting into the
/// same buffer (not counted) whenever an episode ends; returns the allocations of the last
/// `steps` calls.
inline AllocCounts count_step_allocations(Env& env, int warmup_steps, int steps,
                                          CountedSteps which = CountedSteps::kAll) {
  ResetResult reset;
  reset.obs = env.observation_space().zeros();
  env.reset_into(reset, /*seed=*/0);
  StepResult step;
  step.obs = env.observation_space().zeros();
  Rng rng(1);
  std::vector<Value> actions;
  for (int i = 0; i < warmup_steps + steps; ++i) actions.push_back(env.action_space().sample(rng));
  AllocCounts total;
  for (int i = 0; i < warmup_steps + steps; ++i) {
    const Value& action = actions[static_cast<std::size_t>(i)];
    const AllocCounts counts = count_allocations([&] { env.step_into(action, step); });
    const bool ended = step.terminated || step.truncated;
    if (i >= warmup_steps && !(ended && which == CountedSteps::kWithinEpisodes)) total += counts;
    if (ended) env.reset_into(reset);
  }
  return total;
}

}  // namespace pixelgym::testing
