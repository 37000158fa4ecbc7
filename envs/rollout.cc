#include "pixelgym/envs/rollout.h"

namespace pixelgym {

RandomRollout::RandomRollout(Env& env, std::uint64_t seed)
    : env_(env), action_rng_(seed), reset_observation_(env.reset(seed).obs) {}

const StepResult& RandomRollout::step(bool reset_when_done) {
  if (needs_reset_) reset();
  last_step_ = env_.step(env_.action_space().sample(action_rng_));
  ++steps_;
  current_episode_.episode_return += last_step_.reward;
  ++current_episode_.length;
  after_reset_ = false;
  episode_ended_ = last_step_.terminated || last_step_.truncated;
  if (episode_ended_) {
    current_episode_.terminated = last_step_.terminated;
    last_episode_ = current_episode_;
    current_episode_ = {};
    ++episodes_;
    needs_reset_ = true;
    if (reset_when_done) reset();
  }
  return last_step_;
}

void RandomRollout::reset() {
  reset_observation_ = env_.reset().obs;
  after_reset_ = true;
  needs_reset_ = false;
}

const EpisodeSummary& RandomRollout::finish_episode(bool reset_when_done) {
  do {
    step(reset_when_done);
  } while (!episode_ended_);
  return last_episode_;
}

}  // namespace pixelgym
