// RandomRollout: an env driven by seeded uniform random actions — the loop behind check_env and
// `pixelgym snapshot | rollout | bench`.
#pragma once

#include <cstdint>

#include "pixelgym/envs/env.h"
#include "pixelgym/envs/rng.h"

namespace pixelgym {

/// One finished episode.
struct EpisodeSummary {
  /// The sum of the episode's rewards.
  double episode_return = 0.0;
  /// Its steps.
  std::int64_t length = 0;
  /// True when the task ended it, false when it was truncated.
  bool terminated = false;
};

/// Drives `env` with uniform random actions: `reset(seed)` once, then actions sampled from a
/// generator of its own seeded with the same `seed` (not the action space's own generator), and,
/// when an episode ends, `reset()` without a seed, which continues the env's generator. The same
/// env, seed and number of steps therefore give the same trajectory.
///
/// A step copies no observation (what `step()` returns is kept, not copied). The env must outlive
/// the rollout; env errors (ResetNeeded, std::invalid_argument, ...)
/// propagate unchanged.
class RandomRollout {
 public:
  /// Resets `env` with `seed` and seeds the action generator with `seed`.
  RandomRollout(Env& env, std::uint64_t seed);

  /// Samples an action and steps with it. When the step ends the episode, `episode_ended()`
  /// becomes true, `last_episode()` describes it and, when `reset_when_done`, the env is reset
  /// (unseeded; `observation()` is then the new episode's first). With `reset_when_done` false the
  /// env is left at the end of the episode, e.g. so that `render()` shows its last frame; the next
  /// `step()` resets it first. Returns the step's own result (the final observation of an episode
  /// that ended, not the reset's).
  const StepResult& step(bool reset_when_done = true);

  /// Steps until the current episode ends and returns its summary; see `step()` for
  /// `reset_when_done`.
  const EpisodeSummary& finish_episode(bool reset_when_done = true);

  /// The latest observation: the reset's, or the latest step's unless a reset followed it.
  const Value& observation() const { return after_reset_ ? reset_observation_ : last_step_.obs; }
  /// Whether the latest step ended an episode.
  bool episode_ended() const { return episode_ended_; }
  /// The latest finished episode; all zero before one has ended.
  const EpisodeSummary& last_episode() const { return last_episode_; }
  /// Episodes finished so far.
  std::int64_t episodes() const { return episodes_; }
  /// Steps taken so far, over every episode.
  std::int64_t steps() const { return steps_; }

 private:
  void reset();  // unseeded, continuing the env's generator

  Env& env_;
  Rng action_rng_;
  Value reset_observation_;
  StepResult last_step_;
  bool after_reset_ = true;  // whether observation() is the reset's
  bool episode_ended_ = false;
  bool needs_reset_ = false;
  EpisodeSummary current_episode_;
  EpisodeSummary last_episode_;
  std::int64_t episodes_ = 0;
  std::int64_t steps_ = 0;
};

}  // namespace pixelgym
