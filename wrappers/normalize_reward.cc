#include "pixelgym/wrappers/normalize_reward.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace pixelgym::wrappers {

NormalizeReward::NormalizeReward(std::unique_ptr<Env> env, double gamma, double epsilon)
    : Wrapper(std::move(env)), gamma_(gamma), epsilon_(epsilon) {
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
}

void NormalizeReward::set_statistics(RunningStatistics statistics) {
  const std::string reason = statistics.invalid_reason(1);
  if (!reason.empty()) {
    throw std::invalid_argument("NormalizeReward: statistics for 1 element expected: " + reason);
  }
  statistics_ = std::move(statistics);
}

void NormalizeReward::do_reset(std::optional<std::uint64_t> seed, const Options& options,
                               ResetResult& out) {
  return_ = 0.0;
  env_->reset_into(out, seed, options);
}

void NormalizeReward::do_step(const Value& action, StepResult& out) {
  env_->step_into(action, out);
  return_ = gamma_ * return_ + out.reward;
  if (update_statistics_) {
    const double sample = return_;
    statistics_.update([sample](std::size_t /*i*/) { return sample; });
  }
  out.reward /= std::sqrt(statistics_.var[0] + epsilon_);
  if (out.terminated || out.truncated) return_ = 0.0;
}

}  // namespace pixelgym::wrappers
