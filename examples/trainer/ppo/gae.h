// Generalized advantage estimation (Schulman et al. 2016) over a rollout of T steps x N envs,
// with time limits done right: a truncated step bootstraps from the value of its final
// observation, a terminated one does not. Torch-free: plain arrays in, plain arrays out.
#pragma once

#include <cstdint>
#include <vector>

namespace pixelgym::ppo {

/// One rollout as GAE reads it. Every per-step array holds num_steps * num_envs entries in
/// step-major order (entry t * num_envs + n is env n's step t), as RolloutStorage keeps them.
///
/// The rollout is the one a vector env in SameStep autoreset mode gives: step t of env n takes
/// action a_t in observation s_t and returns reward r_t and the flags; when either flag is set
/// the env was reset within that step, so s_{t+1} is the first observation of the next episode
/// and the episode's last observation is in infos["final_obs"]. (NextStep mode inserts a step
/// that only resets; such rollouts are not what this function expects.)
struct GaeInputs {
  std::int64_t num_steps = 0;
  std::int64_t num_envs = 0;
  /// r_t: the reward of step t.
  const float* rewards = nullptr;
  /// V(s_t): the value of the observation step t acted in.
  const float* values = nullptr;
  /// Step t ended its episode by the task's own end: nothing follows, the target is r_t alone.
  /// A step both terminated and truncated counts as terminated (Gymnasium's rule).
  const std::uint8_t* terminated = nullptr;
  /// Step t was cut off (a time limit): the target is r_t + gamma V(final observation).
  const std::uint8_t* truncated = nullptr;
  /// V(final observation of step t), read only where truncated (and not terminated); other
  /// entries are ignored (RolloutStorage leaves them 0). This is the value of
  /// infos["final_obs"]'s row under SameStep autoreset.
  const float* final_values = nullptr;
  /// V(s_T), num_envs entries: the value of the observation after the rollout's last step,
  /// bootstrapping envs whose episode goes on past the rollout.
  const float* last_values = nullptr;
};

/// What compute_gae writes, num_steps * num_envs entries each, step-major.
struct GaeOutputs {
  /// A_t = delta_t + gamma lambda A_{t+1} (the sum stops at a step that ended an episode), with
  /// delta_t = r_t + gamma V_next - V(s_t), V_next = 0 when terminated, V(final observation)
  /// when truncated, else V(s_{t+1}) (last_values for t = T - 1).
  std::vector<float> advantages;
  /// The value targets: A_t + V(s_t) (the lambda-returns).
  std::vector<float> returns;
};

/// GAE(gamma, lambda) of a rollout. Accumulates in double. Throws std::invalid_argument when a
/// size is < 1 or a pointer is null, or unless 0 <= gamma <= 1 and 0 <= lambda <= 1.
GaeOutputs compute_gae(const GaeInputs& inputs, double gamma, double lambda);

}  // namespace pixelgym::ppo
