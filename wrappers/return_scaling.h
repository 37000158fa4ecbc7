// wrappers::ReturnScaling: the reward scaling of vector::NormalizeReward without the wrapper, for
// a learner that scales the rewards it is given (PPO's trainer) while the env stays the run's.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pixelgym/wrappers/running_statistics.h"

namespace pixelgym::wrappers {

/// Each of n envs keeps a discounted return R_i = gamma * R_i + r_i; every step merges the
/// returns of the envs that stepped into one RunningStatistics of one element (from var 1 and
/// count 1e-4) as one batch (RunningStatistics::update_batch), and then every reward r_i becomes
/// r_i / sqrt(var + epsilon). R_i goes back to 0 after a step that ends env i's episode and when
/// env i is reset. vector::NormalizeReward is this over a vector env (its doc says why each rule).
/// Errors name `owner` (the wrapper or trainer that holds it).
class ReturnScaling {
 public:
  /// Throws std::invalid_argument naming `owner` unless 0 <= gamma <= 1 and epsilon is finite
  /// and > 0.
  ReturnScaling(std::size_t num_envs, double gamma, double epsilon, std::string owner);

  double gamma() const { return gamma_; }
  double epsilon() const { return epsilon_; }
  /// Each env's discounted return R_i of its current episode so far (num_envs entries).
  const std::vector<double>& discounted_returns() const { return returns_; }
  /// Replaces them (restoring a checkpoint). Throws std::invalid_argument naming the owner
  /// unless `returns` has num_envs entries, all finite; nothing changes then.
  void set_discounted_returns(std::vector<double> returns);

  /// Whether steps update the statistics (true at construction); false freezes the variance.
  bool update_statistics() const { return update_statistics_; }
  void set_update_statistics(bool update) { update_statistics_ = update; }

  /// The running statistics of the returns (one element).
  const RunningStatistics& statistics() const { return statistics_; }
  /// Replaces them. Throws std::invalid_argument naming the owner when they are not valid
  /// statistics of one element; nothing changes then.
  void set_statistics(RunningStatistics statistics);

  /// R_i = 0 for every env, or (with a mask of num_envs entries) for the masked ones.
  void reset(const bool* mask = nullptr);
  /// One step of every env: `rewards`, and whether it ended each env's episode (`ended`). The
  /// returns of the envs not `skipped` (null: none skipped) are merged as one batch; `out[i]`
  /// (num_envs entries; may be `rewards`) is rewards[i] / sqrt(var + epsilon); R_i = 0 where ended.
  void scale(const double* rewards, const std::uint8_t* ended, const std::uint8_t* skipped,
             double* out);

 private:
  double gamma_;
  double epsilon_;
  std::string owner_;
  bool update_statistics_ = true;
  RunningStatistics statistics_ = RunningStatistics::initial(1);
  std::vector<double> returns_;
  std::vector<double> merged_;  // the returns one step merges (capacity num_envs)
};

}  // namespace pixelgym::wrappers
