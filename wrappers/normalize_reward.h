// NormalizeReward: scales rewards by the running standard deviation of the discounted return
// (gymnasium.wrappers.NormalizeReward), with statistics that can be frozen and checkpointed.
#pragma once

#include <memory>
#include <string>

#include "pixelgym/envs/wrapper.h"
#include "pixelgym/wrappers/running_statistics.h"

namespace pixelgym::wrappers {

/// Each step's reward r becomes r / sqrt(var + epsilon), where var is the running variance
/// (RunningStatistics of one element: Gymnasium's RunningMeanStd, from var 1 and count 1e-4) of
/// the discounted return R = gamma * R + r, which is updated with this step's R first. As in
/// Gymnasium, the mean is not subtracted (openai/baselines#538). Observations, flags and info pass
/// through.
///
/// R starts at 0 and goes back to 0 after a step that ends the episode (terminated or truncated)
/// and on every reset, so each episode's return is its own. (Gymnasium 1.x's code multiplies the
/// previous R by (1 - terminated) of the current step and never resets on truncation or reset(),
/// so a truncated episode's return leaks into the next one; here both ends behave the same.)
///
/// `set_update_statistics(false)` freezes the variance (for evaluation); `statistics()` /
/// `set_statistics()` read and write it (RunningStatistics::to_value / from_value for
/// checkpoints). Allocates nothing per step.
class NormalizeReward final : public Wrapper {
 public:
  /// Throws std::invalid_argument unless 0 <= gamma <= 1 and epsilon is finite and > 0.
  explicit NormalizeReward(std::unique_ptr<Env> env, double gamma = 0.99, double epsilon = 1e-8);

  /// The discount of the return R.
  double gamma() const { return gamma_; }
  /// The constant added to the variance before its square root.
  double epsilon() const { return epsilon_; }
  /// The discounted return R of the current episode so far.
  double discounted_return() const { return return_; }

  /// Whether steps update the statistics (true at construction).
  bool update_statistics() const { return update_statistics_; }
  /// false freezes the variance (rewards are still scaled by it); true resumes.
  void set_update_statistics(bool update) { update_statistics_ = update; }

  /// The running statistics of R (one element).
  const RunningStatistics& statistics() const { return statistics_; }
  /// Replaces them (restoring a checkpoint). Throws std::invalid_argument naming the wrapper when
  /// they are not valid statistics of one element; nothing changes then.
  void set_statistics(RunningStatistics statistics);

 protected:
  std::string type_name() const override { return "NormalizeReward"; }
  void do_reset(std::optional<std::uint64_t> seed, const Options& options,
                ResetResult& out) override;
  void do_step(const Value& action, StepResult& out) override;

 private:
  double gamma_;
  double epsilon_;
  double return_ = 0.0;
  bool update_statistics_ = true;
  RunningStatistics statistics_ = RunningStatistics::initial(1);
};

}  // namespace pixelgym::wrappers
