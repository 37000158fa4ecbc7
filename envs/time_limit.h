// TimeLimit: truncates episodes after a number of steps (gymnasium.wrappers.TimeLimit).
#pragma once

#include <cstdint>

#include "pixelgym/envs/wrapper.h"

namespace pixelgym {

/// Sets `truncated` on the step that makes the episode `max_episode_steps` long. It lives in
/// envs/ rather than wrappers/ because the registry applies it to every env whose spec has
/// `max_episode_steps`.
class TimeLimit final : public Wrapper {
 public:
  /// Throws std::invalid_argument unless max_episode_steps > 0.
  TimeLimit(std::unique_ptr<Env> env, std::int64_t max_episode_steps);

  /// The episode length, in steps, at which it truncates.
  std::int64_t max_episode_steps() const { return max_episode_steps_; }
  /// Steps taken in the current episode.
  std::int64_t elapsed_steps() const { return elapsed_steps_; }

 protected:
  std::string type_name() const override { return "TimeLimit"; }
  void do_reset(std::optional<std::uint64_t> seed, const Options& options,
                ResetResult& out) override;
  void do_step(const Value& action, StepResult& out) override;

 private:
  std::int64_t max_episode_steps_;
  std::int64_t elapsed_steps_ = 0;
};

}  // namespace pixelgym
