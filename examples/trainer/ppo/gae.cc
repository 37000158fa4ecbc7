#include "examples/trainer/ppo/gae.h"

#include <stdexcept>
#include <string>

namespace pixelgym::ppo {

GaeOutputs compute_gae(const GaeInputs& in, double gamma, double lambda) {
  if (in.num_steps < 1 || in.num_envs < 1) {
    throw std::invalid_argument("compute_gae: num_steps and num_envs must be >= 1, got " +
                                std::to_string(in.num_steps) + " and " +
                                std::to_string(in.num_envs));
  }
  if (in.rewards == nullptr || in.values == nullptr || in.terminated == nullptr ||
      in.truncated == nullptr || in.final_values == nullptr || in.last_values == nullptr) {
    throw std::invalid_argument("compute_gae: every input array must be given (one is null)");
  }
  if (!(gamma >= 0.0 && gamma <= 1.0) || !(lambda >= 0.0 && lambda <= 1.0)) {
    throw std::invalid_argument("compute_gae: gamma and lambda must be in [0, 1], got " +
                                std::to_string(gamma) + " and " + std::to_string(lambda));
  }
  const std::int64_t steps = in.num_steps;
  const std::int64_t envs = in.num_envs;
  GaeOutputs out;
  out.advantages.assign(static_cast<std::size_t>(steps * envs), 0.0f);
  out.returns.assign(out.advantages.size(), 0.0f);
  for (std::int64_t n = 0; n < envs; ++n) {
    double next_advantage = 0.0;  // A_{t+1} of the same episode
    for (std::int64_t t = steps - 1; t >= 0; --t) {
      const std::int64_t i = t * envs + n;
      double next_value;
      bool continues;  // s_{t+1} belongs to the episode of step t
      if (in.terminated[i] != 0) {
        next_value = 0.0;
        continues = false;
      } else if (in.truncated[i] != 0) {
        next_value = in.final_values[i];
        continues = false;
      } else {
        next_value = t + 1 < steps ? in.values[i + envs] : in.last_values[n];
        continues = true;
      }
      const double delta = in.rewards[i] + gamma * next_value - in.values[i];
      const double advantage = delta + (continues ? gamma * lambda * next_advantage : 0.0);
      next_advantage = advantage;
      out.advantages[static_cast<std::size_t>(i)] = static_cast<float>(advantage);
      out.returns[static_cast<std::size_t>(i)] = static_cast<float>(advantage + in.values[i]);
    }
  }
  return out;
}

}  // namespace pixelgym::ppo
