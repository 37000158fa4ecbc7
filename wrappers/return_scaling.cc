#include "pixelgym/wrappers/return_scaling.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace pixelgym::wrappers {

ReturnScaling::ReturnScaling(std::size_t num_envs, double gamma, double epsilon, std::string owner)
    : gamma_(gamma), epsilon_(epsilon), owner_(std::move(owner)) {
  if (!(gamma >= 0.0 && gamma <= 1.0)) {
    std::ostringstream text;
    text << owner_ << ": gamma must be in [0, 1], got " << gamma;
    throw std::invalid_argument(text.str());
  }
  if (!std::isfinite(epsilon) || !(epsilon > 0.0)) {
    std::ostringstream text;
    text << owner_ << ": epsilon must be finite and > 0, got " << epsilon;
    throw std::invalid_argument(text.str());
  }
  returns_.assign(num_envs, 0.0);
  merged_.reserve(num_envs);
}

void ReturnScaling::set_statistics(RunningStatistics statistics) {
  const std::string reason = statistics.invalid_reason(1);
  if (!reason.empty()) {
    throw std::invalid_argument(owner_ + ": statistics for 1 element expected: " + reason);
  }
  statistics_ = std::move(statistics);
}

void ReturnScaling::set_discounted_returns(std::vector<double> returns) {
  if (returns.size() != returns_.size()) {
    throw std::invalid_argument(owner_ + ": " + std::to_string(returns_.size()) +
                                " discounted returns expected (num_envs), got " +
                                std::to_string(returns.size()));
  }
  for (const double r : returns) {
    if (!std::isfinite(r)) {
      throw std::invalid_argument(owner_ + ": a discounted return is " + std::to_string(r));
    }
  }
  returns_ = std::move(returns);
}

void ReturnScaling::reset(const bool* mask) {
  for (std::size_t i = 0; i < returns_.size(); ++i) {
    if (mask == nullptr || mask[i]) returns_[i] = 0.0;
  }
}

void ReturnScaling::scale(const double* rewards, const std::uint8_t* ended,
                          const std::uint8_t* skipped, double* out) {
  merged_.clear();
  for (std::size_t i = 0; i < returns_.size(); ++i) {
    if (skipped != nullptr && skipped[i] != 0) continue;
    returns_[i] = gamma_ * returns_[i] + rewards[i];
    merged_.push_back(returns_[i]);
  }
  if (update_statistics_) {
    statistics_.update_batch(merged_.size(),
                             [this](std::size_t row, std::size_t /*i*/) { return merged_[row]; });
  }
  const double scale = std::sqrt(statistics_.var[0] + epsilon_);
  for (std::size_t i = 0; i < returns_.size(); ++i) {
    out[i] = rewards[i] / scale;
    if (ended[i] != 0) returns_[i] = 0.0;
  }
}

}  // namespace pixelgym::wrappers
