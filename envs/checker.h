// check_env: the C++ counterpart of gymnasium.utils.env_checker.check_env.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pixelgym/envs/env.h"

namespace pixelgym {

/// The outcome of one named check.
struct CheckResult {
  /// The check's name, as listed at check_env ("reset_seed", "step", ...).
  std::string name;
  /// Whether the check held.
  bool passed = false;
  /// Why it failed; empty when it passed.
  std::string reason;
};

/// Every check that `check_env` ran, in order.
struct CheckReport {
  std::vector<CheckResult> results;
  /// True when every check passed.
  bool passed() const;
  /// The checks that failed, in order (a copy).
  std::vector<CheckResult> failures() const;
};

/// How hard `check_env` pushes.
struct CheckOptions {
  /// Seed for resets and for the random actions.
  std::uint64_t seed = 0;
  /// Random steps per trajectory (episodes that end are reset and continued).
  int num_steps = 100;
};

/// Runs every check on `env` and reports each failure with its reason (an exception thrown by
/// the env fails the check that triggered it, and the remaining checks still run). The checks:
///  - observation_space, action_space: 16 seeded samples are each contained in the space.
///  - reset: `reset(seed)` returns an observation inside observation_space (dtype included).
///  - reset_seed: `reset(seed)` twice gives identical observations.
///  - reset_unseeded: `reset()` after `reset(seed)` continues the seeded generator — repeatable,
///    and (for envs whose start depends on the seed) not a reseed to a fixed state.
///  - step: random steps return observations inside the space and finite rewards.
///  - step_determinism: the same seed and actions give identical observations, rewards and flags.
///  - observation_aliasing: an observation returned by reset() or step() does not change when
///    later steps run (observations may share memory that is never written again).
///  - buffer_path: `reset_into` / `step_into` write into the caller's arrays (no array of the
///    env's own swapped in) and give what `reset` / `step` give for the same seed and actions.
///  - render: `render()` returns an (H, W, 3) uint8 array, of metadata().render_shape when set.
///  - metadata: render_modes holds "rgb_array" and render_fps > 0.
///  - close: `close()` twice raises nothing. The env is closed afterwards.
CheckReport check_env(Env& env, const CheckOptions& options = {});

}  // namespace pixelgym
