// A committed policy file (tests/envs/tasks/controllers/*.policy.json) played beside random
// actions on the env it names: what the trained-policy tests compare.
#pragma once

#include <cstdint>
#include <iostream>
#include <memory>
#include <string>

#include "pixelgym/envs/registry.h"
#include "pixelgym/testing/mlp_policy.h"
#include "tests/envs/tasks/scripted.h"

namespace pixelgym::testing {

/// Mean returns of a policy and of random actions over the same seeds.
struct TrainedAndRandom {
  std::string env_id;  // the env the policy file names
  double trained = 0.0;
  double random = 0.0;
};

/// Plays the policy file `name` (in tests/envs/tasks/controllers/) and a random policy on the env
/// the file names, one episode each from seeds 2, 3 and 4 (which no training run trained or
/// evaluated on: theirs were 0, 1, ... and 1000000 on), and prints both means.
inline TrainedAndRandom play_trained_policy(const std::string& name) {
  const MlpPolicy policy =
      MlpPolicy::load(std::string(PIXELGYM_SOURCE_DIR) + "/tests/envs/tasks/controllers/" + name);
  std::unique_ptr<Env> env = make(policy.env_id(), policy.env_kwargs());
  TrainedAndRandom result{policy.env_id()};
  for (std::uint64_t seed = 2; seed < 5; ++seed) {
    result.trained +=
        episode_return(*env, seed, [&](const Value& obs) { return Value(policy.act(obs)); }) / 3.0;
    result.random += episode_return(*env, seed, random_policy(*env, seed)) / 3.0;
  }
  std::cout << result.env_id << " mean return over seeds 2-4: trained " << result.trained
            << ", random " << result.random << "\n";
  return result;
}

}  // namespace pixelgym::testing
