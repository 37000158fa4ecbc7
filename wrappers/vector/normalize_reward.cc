#include "pixelgym/wrappers/vector/normalize_reward.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace pixelgym::vector {

NormalizeReward::NormalizeReward(std::unique_ptr<VectorEnv> env, double gamma, double epsilon)
    : VectorWrapper(std::move(env)), gamma_(gamma), epsilon_(epsilon) {
  if (!(gamma >= 0.0 && gamma <= 1.0)) {
    std::ostringstream text;
    text << "NormalizeReward: gamma must be in [0, 1], got " << gamma;
    throw std::invalid_argument(text.str());
  }
  if (!std::isfinite(epsilon) || !(epsilon > 0.0)) {
    std::ostringstream text;
    text << "NormalizeReward: epsilon must be finite and > 0, got " << epsilon;
    throw std::invalid_argument(text.str());
  }
  const auto n = static_cast<std::size_t>(num_envs());
  returns_.assign(n, 0.0);
  ended_.assign(n, 0);
  merged_.reserve(n);
  rewards_ = Array(DType::kFloat64, {num_envs()});
  result_.rewards = rewards_;
}

void NormalizeReward::set_statistics(wrappers::RunningStatistics statistics) {
  const std::string reason = statistics.invalid_reason(1);
  if (!reason.empty()) {
    throw std::invalid_argument("NormalizeReward: statistics for 1 element expected: " + reason);
  }
  statistics_ = std::move(statistics);
}

void NormalizeReward::set_discounted_returns(std::vector<double> returns) {
  if (returns.size() != returns_.size()) {
    throw std::invalid_argument("NormalizeReward: " + std::to_string(returns_.size()) +
                                " discounted returns expected (num_envs), got " +
                                std::to_string(returns.size()));
  }
  for (const double r : returns) {
    if (!std::isfinite(r)) {
      throw std::invalid_argument("NormalizeReward: a discounted return is " + std::to_string(r));
    }
  }
  returns_ = std::move(returns);
}

const VectorResetResult& NormalizeReward::do_reset(std::optional<std::uint64_t> seed,
                                                   const Options& options,
                                                   const Array* reset_mask) {
  const VectorResetResult& result = reset_inner(seed, options, reset_mask);
  for (std::size_t i = 0; i < returns_.size(); ++i) {
    if (reset_mask != nullptr && !reset_mask->data<bool>()[i]) continue;
    returns_[i] = 0.0;
    ended_[i] = 0;
  }
  return result;
}

const VectorStepResult& NormalizeReward::do_step(const Value& actions) {
  const VectorStepResult& inner = step_inner(actions);
  view(inner.obs, result_.obs);
  view(inner.terminated, result_.terminated);
  view(inner.truncated, result_.truncated);
  copy_infos(inner.infos, result_.infos);
  const double* rewards = inner.rewards.data<double>();
  const bool* terminated = inner.terminated.data<bool>();
  const bool* truncated = inner.truncated.data<bool>();
  const bool next_step = autoreset_mode() == AutoresetMode::kNextStep;

  merged_.clear();
  for (std::size_t i = 0; i < returns_.size(); ++i) {
    // NextStep: this step was env i's reset (R_i is 0 since its done); nothing to merge.
    if (next_step && ended_[i] != 0) continue;
    returns_[i] = gamma_ * returns_[i] + rewards[i];
    merged_.push_back(returns_[i]);
  }
  if (update_statistics_) {
    statistics_.update_batch(merged_.size(),
                             [this](std::size_t row, std::size_t /*i*/) { return merged_[row]; });
  }
  const double scale = std::sqrt(statistics_.var[0] + epsilon_);
  double* out = rewards_.data<double>();
  for (std::size_t i = 0; i < returns_.size(); ++i) {
    out[i] = rewards[i] / scale;
    ended_[i] = terminated[i] || truncated[i] ? 1 : 0;
    if (ended_[i] != 0) returns_[i] = 0.0;
  }
  return result_;
}

}  // namespace pixelgym::vector
