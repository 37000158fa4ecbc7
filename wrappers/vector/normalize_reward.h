// vector::NormalizeReward: rewards scaled by the running standard deviation of the discounted
// returns, one set of statistics shared across the batch (gymnasium.wrappers.vector.
// NormalizeReward).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "pixelgym/envs/vector/vector_wrapper.h"
#include "pixelgym/wrappers/return_scaling.h"
#include "pixelgym/wrappers/running_statistics.h"

namespace pixelgym::vector {

/// Each env i keeps a discounted return R_i = gamma * R_i + r_i; every step merges the returns of
/// the envs that stepped into one RunningStatistics of one element (Gymnasium's RunningMeanStd,
/// from var 1 and count 1e-4), as one batch (RunningStatistics::update_batch), and then every
/// reward r_i becomes r_i / sqrt(var + epsilon). As in Gymnasium, the mean is not subtracted.
/// Observations, flags and infos pass through.
///
/// As the per-env wrappers::NormalizeReward, and on purpose unlike Gymnasium (which multiplies
/// R_i by 1 - terminated_i of the current step, so that a truncated episode's return leaks into
/// the next one): R_i goes back to 0 after a step that ends env i's episode (terminated or
/// truncated) and when env i is reset (reset(); reset with a mask: the masked envs only), so each
/// episode's return is its own. Under NextStep the step after env i's done is env i's reset
/// (reward 0, no action taken): its R_i is not merged, as the per-env wrapper has no step there
/// (Gymnasium releases up to 1.3.0 merge every row; its development version skips these rows
/// too). So a batch of one env gives exactly the per-env wrapper's rewards and statistics.
///
/// The arithmetic is wrappers::ReturnScaling's (which PPO's trainer also uses, without the
/// wrapper). `set_update_statistics(false)` freezes the variance (for evaluation); `statistics()` /
/// `set_statistics()` read and write it (RunningStatistics::to_value / from_value for
/// checkpoints). Allocates nothing per step beyond copying non-empty infos (VectorWrapper).
class NormalizeReward final : public VectorWrapper {
 public:
  /// Throws std::invalid_argument unless 0 <= gamma <= 1 and epsilon is finite and > 0.
  explicit NormalizeReward(std::unique_ptr<VectorEnv> env, double gamma = 0.99,
                           double epsilon = 1e-8);

  /// The discount of the returns R_i.
  double gamma() const { return scaling_.gamma(); }
  /// The constant added to the variance before its square root.
  double epsilon() const { return scaling_.epsilon(); }
  /// Each env's discounted return R_i of its current episode so far (num_envs entries).
  const std::vector<double>& discounted_returns() const { return scaling_.discounted_returns(); }
  /// Replaces them (restoring a checkpoint). Throws std::invalid_argument naming the wrapper
  /// unless `returns` has num_envs entries, all finite; nothing changes then.
  void set_discounted_returns(std::vector<double> returns) {
    scaling_.set_discounted_returns(std::move(returns));
  }

  /// Whether steps update the statistics (true at construction).
  bool update_statistics() const { return scaling_.update_statistics(); }
  /// false freezes the variance (rewards are still scaled by it); true resumes.
  void set_update_statistics(bool update) { scaling_.set_update_statistics(update); }

  /// The running statistics of the returns (one element).
  const wrappers::RunningStatistics& statistics() const { return scaling_.statistics(); }
  /// Replaces them (restoring a checkpoint). Throws std::invalid_argument naming the wrapper when
  /// they are not valid statistics of one element; nothing changes then.
  void set_statistics(wrappers::RunningStatistics statistics) {
    scaling_.set_statistics(std::move(statistics));
  }

 protected:
  std::string type_name() const override { return "NormalizeReward"; }
  const VectorResetResult& do_reset(std::optional<std::uint64_t> seed, const Options& options,
                                    const Array* reset_mask) override;
  const VectorStepResult& do_step(const Value& actions) override;

 private:
  wrappers::ReturnScaling scaling_;
  std::vector<std::uint8_t> ended_;      // env i's episode ended at the last step
  std::vector<std::uint8_t> was_ended_;  // NextStep: ended_ of the step before (skipped rows)
  Array rewards_;                        // float64 (num_envs,): the results' rewards
  VectorStepResult result_;
};

}  // namespace pixelgym::vector
