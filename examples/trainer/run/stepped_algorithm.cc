#include "pixelgym/trainer/stepped_algorithm.h"

#include <chrono>
#include <stdexcept>
#include <utility>

namespace pixelgym::trainer {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

SteppedAlgorithm::SteppedAlgorithm(EnvLoop& loop, SteppedSettings settings,
                                   std::unique_ptr<StepLearner> learner)
    : settings_(std::move(settings)),
      loop_(&loop),
      learner_(std::move(learner)),
      actions_(loop.zero_actions()) {
  if (!learner_) throw std::invalid_argument("SteppedAlgorithm: the learner is null");
  if (settings_.iteration_env_steps <= 0 || settings_.iteration_env_steps % loop.num_envs() != 0) {
    throw std::invalid_argument(
        "SteppedAlgorithm: iteration_env_steps must be a positive multiple "
        "of the env's num_envs (" +
        std::to_string(loop.num_envs()) + "), got " +
        std::to_string(settings_.iteration_env_steps));
  }
}

IterationStats SteppedAlgorithm::iterate(const StopCheck& stop) {
  if (!loop_->started()) learner_->begin(loop_->reset());
  IterationStats stats;
  LoopTimes times;
  const std::int64_t steps = settings_.iteration_env_steps / loop_->num_envs();
  bool stopped = false;
  for (std::int64_t s = 0; s < steps && !stopped; ++s) {
    auto start = Clock::now();
    learner_->act(loop_->observations(), env_steps_, actions_);
    times.act += seconds_since(start);
    start = Clock::now();
    const vector::VectorStepResult& step = loop_->step(actions_);
    times.env += seconds_since(start);
    learner_->observe(actions_, step);
    for (const double r : loop_->ended_returns(step)) stats.episode_returns.push_back(r);
    env_steps_ += loop_->num_envs();
    stopped = learner_->learn(env_steps_, stop);
    if (!stopped && stop) stopped = stop(env_steps_);
  }
  ++iterations_;
  stats.metrics = learner_->end_iteration(times);
  return stats;
}

void SteppedAlgorithm::set_progress(std::int64_t env_steps, std::int64_t updates) {
  env_steps_ = env_steps;
  iterations_ = updates;
}

}  // namespace pixelgym::trainer
