#include "pixelgym/wrappers/vector/normalize_reward.h"

#include <utility>

namespace pixelgym::vector {

NormalizeReward::NormalizeReward(std::unique_ptr<VectorEnv> env, double gamma, double epsilon)
    : VectorWrapper(std::move(env)),
      scaling_(static_cast<std::size_t>(num_envs()), gamma, epsilon, "NormalizeReward") {
  const auto n = static_cast<std::size_t>(num_envs());
  ended_.assign(n, 0);
  was_ended_.assign(n, 0);
  rewards_ = Array(DType::kFloat64, {num_envs()});
  result_.rewards = rewards_;
}

const VectorResetResult& NormalizeReward::do_reset(std::optional<std::uint64_t> seed,
                                                   const Options& options,
                                                   const Array* reset_mask) {
  const VectorResetResult& result = reset_inner(seed, options, reset_mask);
  const bool* mask = reset_mask != nullptr ? reset_mask->data<bool>() : nullptr;
  scaling_.reset(mask);
  for (std::size_t i = 0; i < ended_.size(); ++i) {
    if (mask == nullptr || mask[i]) ended_[i] = 0;
  }
  return result;
}

const VectorStepResult& NormalizeReward::do_step(const Value& actions) {
  const VectorStepResult& inner = step_inner(actions);
  view(inner.obs, result_.obs);
  view(inner.terminated, result_.terminated);
  view(inner.truncated, result_.truncated);
  copy_infos(inner.infos, result_.infos);
  const bool* terminated = inner.terminated.data<bool>();
  const bool* truncated = inner.truncated.data<bool>();
  // NextStep: a step after env i's done was env i's reset (R_i is 0 since its done); it is
  // skipped, nothing merged.
  const bool next_step = autoreset_mode() == AutoresetMode::kNextStep;
  was_ended_.swap(ended_);
  for (std::size_t i = 0; i < ended_.size(); ++i) {
    ended_[i] = terminated[i] || truncated[i] ? 1 : 0;
  }
  scaling_.scale(inner.rewards.data<double>(), ended_.data(),
                 next_step ? was_ended_.data() : nullptr, rewards_.data<double>());
  return result_;
}

}  // namespace pixelgym::vector
