#include "pixelgym/envs/env.h"

#include "pixelgym/envs/registry.h"

namespace pixelgym {

std::string Env::name() const { return spec() != nullptr ? spec()->id : type_name(); }

Rng& Env::rng() {
  if (!rng_) rng_.emplace(Rng::entropy_seed());
  return *rng_;
}

namespace {

// Throws unless `obs` is laid out as `space` (structure, dtypes, shapes; values not checked).
void require_layout(const Env& env, const Space& space, const Value& obs, const char* method) {
  const std::string reason = space.layout_mismatch(obs);
  if (!reason.empty()) {
    throw std::invalid_argument(env.name() + ": " + method + " buffer is not laid out as " +
                                space.to_string() + ": " + reason);
  }
}

}  // namespace

Value Env::observation_buffer(BufferFor /*call*/) { return observation_space().zeros(); }

ResetResult Env::reset(std::optional<std::uint64_t> seed, const Options& options) {
  ResetResult result;
  result.obs = observation_buffer(BufferFor::kReset);
  reset_into(result, seed, options);
  return result;
}

StepResult Env::step(const Value& action) {
  StepResult result;
  result.obs = observation_buffer(BufferFor::kStep);
  step_into(action, result);
  return result;
}

void Env::reset_into(ResetResult& out, std::optional<std::uint64_t> seed, const Options& options) {
  if (closed_) throw ResetNeeded(name() + ": reset() called after close()");
  require_layout(*this, observation_space(), out.obs, "reset_into()");
  if (seed) {
    rng_.emplace(*seed);
  } else if (!rng_) {
    rng_.emplace(Rng::entropy_seed());
  }
  // Until do_reset returns, the env is in no valid episode.
  has_reset_ = false;
  out.info.clear();
  do_reset(seed, options, out);
  has_reset_ = true;
  episode_over_ = false;
}

void Env::step_into(const Value& action, StepResult& out) {
  if (closed_) throw ResetNeeded(name() + ": step() called after close()");
  if (!has_reset_) throw ResetNeeded(name() + ": step() called before reset(); call reset() first");
  if (episode_over_) {
    throw ResetNeeded(name() +
                      ": step() called after the episode ended (terminated or truncated); "
                      "call reset() to start a new episode");
  }
  const std::string reason = action_space().mismatch(action);  // empty: no allocation
  if (!reason.empty()) {
    throw std::invalid_argument(name() + ": step() action: " + action.to_string() + " is not in " +
                                action_space().to_string() + ": " + reason);
  }
  require_layout(*this, observation_space(), out.obs, "step_into()");
  // Should do_step throw, the episode is in an unknown state: require a reset.
  episode_over_ = true;
  out.reward = 0.0;
  out.terminated = false;
  out.truncated = false;
  out.info.clear();
  do_step(action, out);
  episode_over_ = out.terminated || out.truncated;
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
