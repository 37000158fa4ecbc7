#include "pixelgym/envs/time_limit.h"

#include <stdexcept>
#include <string>

namespace pixelgym {

TimeLimit::TimeLimit(std::unique_ptr<Env> env, std::int64_t max_episode_steps)
    : Wrapper(std::move(env)), max_episode_steps_(max_episode_steps) {
  if (max_episode_steps <= 0) {
    throw std::invalid_argument(name() + ": max_episode_steps must be positive, got " +
                                std::to_string(max_episode_steps));
  }
}

void TimeLimit::do_reset(std::optional<std::uint64_t> seed, const Options& options,
                         ResetResult& out) {
  elapsed_steps_ = 0;
  env_->reset_into(out, seed, options);
}

void TimeLimit::do_step(const Value& action, StepResult& out) {
  env_->step_into(action, out);
  ++elapsed_steps_;
  if (elapsed_steps_ >= max_episode_steps_) out.truncated = true;
}

}  // namespace pixelgym
