// Runs one episode of an env under a policy and returns its total reward.
#pragma once

#include <functional>

#include "pixelgym/envs/env.h"

namespace pixelgym::testing {

/// Resets with `seed` and steps `policy(observation)` until the episode ends.
inline double episode_return(Env& env, std::uint64_t seed,
                             const std::function<Value(const Value&)>& policy) {
  Value obs = env.reset(seed).obs;
  double total = 0.0;
  for (;;) {
    const StepResult step = env.step(policy(obs));
    total += step.reward;
    obs = step.obs;
    if (step.terminated || step.truncated) return total;
  }
}

/// A uniform random policy drawing from a generator seeded with `seed`.
inline std::function<Value(const Value&)> random_policy(const Env& env, std::uint64_t seed) {
  auto rng = std::make_shared<Rng>(seed);
  const Space* space = &const_cast<Env&>(env).action_space();
  return [rng, space](const Value&) { return space->sample(*rng); };
}

/// Element `i` of float32 state array `key`.
inline double state(const Value& obs, const std::string& key, int i) {
  return obs.dict().at(key).array().data<float>()[i];
}

}  // namespace pixelgym::testing
