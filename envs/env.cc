#include "envs/env.h"

#include "envs/registry.h"

namespace pixelgym {

std::string Env::name() const { return spec() != nullptr ? spec()->id : type_name(); }

Rng& Env::rng() {
  if (!rng_) rng_.emplace(Rng::entropy_seed());
  return *rng_;
}

ResetResult Env::reset(std::optional<std::uint64_t> seed, const Options& options) {
  if (closed_) throw ResetNeeded(name() + ": reset() called after close()");
  if (seed) {
    rng_.emplace(*seed);
  } else if (!rng_) {
    rng_.emplace(Rng::entropy_seed());
  }
  // Until do_reset returns, the env is in no valid episode.
  has_reset_ = false;
  ResetResult result = do_reset(seed, options);
  has_reset_ = true;
  episode_over_ = false;
  return result;
}

StepResult Env::step(const Value& action) {
  if (closed_) throw ResetNeeded(name() + ": step() called after close()");
  if (!has_reset_) throw ResetNeeded(name() + ": step() called before reset(); call reset() first");
  if (episode_over_) {
    throw ResetNeeded(name() +
                      ": step() called after the episode ended (terminated or truncated); "
                      "call reset() to start a new episode");
  }
  require_contains(action_space(), action, name() + ": step() action");
  // Should do_step throw, the episode is in an unknown state: require a reset.
  episode_over_ = true;
  StepResult result = do_step(action);
  episode_over_ = result.terminated || result.truncated;
  return result;
}

Array Env::render() {
  if (closed_) throw ResetNeeded(name() + ": render() called after close()");
  if (!has_reset_) {
    throw ResetNeeded(name() + ": render() called before reset(); call reset() first");
  }
  return do_render();
}

void Env::close() {
  if (closed_) return;
  closed_ = true;
  do_close();
}

}  // namespace pixelgym
