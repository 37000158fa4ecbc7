// The README's first example: make an env, reset it with a seed, step it with random actions.
#include <iostream>

#include "envs/registry.h"

int main() {
  auto env = pixelgym::make("GridWorld-v0");
  auto [obs, info] = env->reset(/*seed=*/42);
  double episode_return = 0.0;
  for (bool done = false; !done;) {
    auto step = env->step(env->action_space().sample());
    episode_return += step.reward;
    done = step.terminated || step.truncated;
  }
  std::cout << "return " << episode_return << "\n";
}
