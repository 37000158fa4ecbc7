#include "envs/wrapper.h"

#include <stdexcept>

namespace pixelgym {

Wrapper::Wrapper(std::unique_ptr<Env> env) : env_(std::move(env)) {
  if (env_ == nullptr) throw std::invalid_argument("Wrapper: the env to wrap is null");
}

ResetResult Wrapper::do_reset(std::optional<std::uint64_t> seed, const Options& options) {
  return env_->reset(seed, options);
}

StepResult Wrapper::do_step(const Value& action) { return env_->step(action); }

Array Wrapper::do_render() { return env_->render(); }

void Wrapper::do_close() { env_->close(); }

const Space& ObservationWrapper::observation_space() const {
  return observation_space_ != nullptr ? *observation_space_ : env_->observation_space();
}

void ObservationWrapper::set_observation_space(SpacePtr space) {
  if (space == nullptr) throw std::invalid_argument(name() + ": observation space is null");
  observation_space_ = std::move(space);
}

ResetResult ObservationWrapper::do_reset(std::optional<std::uint64_t> seed,
                                         const Options& options) {
  ResetResult result = env_->reset(seed, options);
  result.obs = observation(result.obs);
  return result;
}

StepResult ObservationWrapper::do_step(const Value& action) {
  StepResult result = env_->step(action);
  result.obs = observation(result.obs);
  return result;
}

const Space& ActionWrapper::action_space() const {
  return action_space_ != nullptr ? *action_space_ : env_->action_space();
}

void ActionWrapper::set_action_space(SpacePtr space) {
  if (space == nullptr) throw std::invalid_argument(name() + ": action space is null");
  action_space_ = std::move(space);
}

StepResult ActionWrapper::do_step(const Value& action) { return env_->step(this->action(action)); }

StepResult RewardWrapper::do_step(const Value& action) {
  StepResult result = env_->step(action);
  result.reward = reward(result.reward);
  return result;
}

}  // namespace pixelgym
