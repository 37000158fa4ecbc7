#include "pixelgym/envs/wrapper.h"

#include <stdexcept>
#include <utility>

namespace pixelgym {

Wrapper::Wrapper(std::unique_ptr<Env> env) : env_(std::move(env)) {
  if (env_ == nullptr) throw std::invalid_argument("Wrapper: the env to wrap is null");
}

Value Wrapper::observation_buffer(BufferFor call) {
  if (&observation_space() != &env_->observation_space()) return observation_space().zeros();
  return env_->observation_buffer(call);
}

void Wrapper::do_reset(std::optional<std::uint64_t> seed, const Options& options,
                       ResetResult& out) {
  env_->reset_into(out, seed, options);
}

void Wrapper::do_step(const Value& action, StepResult& out) { env_->step_into(action, out); }

Array Wrapper::do_render() { return env_->render(); }

void Wrapper::do_close() { env_->close(); }

const Space& ObservationWrapper::observation_space() const {
  return observation_space_ != nullptr ? *observation_space_ : env_->observation_space();
}

Value ObservationWrapper::observation_buffer(BufferFor /*call*/) {
  return observation_space().zeros();
}

void ObservationWrapper::set_observation_space(SpacePtr space) {
  if (space == nullptr) throw std::invalid_argument(name() + ": observation space is null");
  observation_space_ = std::move(space);
}

void ObservationWrapper::do_reset(std::optional<std::uint64_t> seed, const Options& options,
                                  ResetResult& out) {
  if (!inner_obs_) inner_obs_ = env_->observation_space().zeros();
  {
    SwapBack swap(out.obs, *inner_obs_);
    env_->reset_into(out, seed, options);
  }
  observation(*inner_obs_, out.obs);
}

void ObservationWrapper::do_step(const Value& action, StepResult& out) {
  if (!inner_obs_) inner_obs_ = env_->observation_space().zeros();
  {
    SwapBack swap(out.obs, *inner_obs_);
    env_->step_into(action, out);
  }
  observation(*inner_obs_, out.obs);
}

const Space& ActionWrapper::action_space() const {
  return action_space_ != nullptr ? *action_space_ : env_->action_space();
}

void ActionWrapper::set_action_space(SpacePtr space) {
  if (space == nullptr) throw std::invalid_argument(name() + ": action space is null");
  action_space_ = std::move(space);
}

void ActionWrapper::do_step(const Value& action, StepResult& out) {
  if (!inner_action_) inner_action_ = env_->action_space().zeros();
  this->action(action, *inner_action_);
  env_->step_into(*inner_action_, out);
}

void RewardWrapper::do_step(const Value& action, StepResult& out) {
  env_->step_into(action, out);
  out.reward = reward(out.reward);
}

}  // namespace pixelgym
