// GridWorld-v0 vector envs for the env-loop tests (SameStep autoreset, as the off-policy
// learners need).
#pragma once

#include <memory>

#include "pixelgym/envs/vector/make_vec.h"

namespace pixelgym::trainer::test_envs {

inline std::unique_ptr<vector::VectorEnv> grid_envs(int num_envs) {
  vector::VectorOptions options;
  options.autoreset = vector::AutoresetMode::kSameStep;
  return vector::make_vec("GridWorld-v0", num_envs, {}, nullptr, options);
}

}  // namespace pixelgym::trainer::test_envs
