// vector::NormalizeObservation: a Box observation (or one Dict key) normalized with running
// statistics shared across the batch (gymnasium.wrappers.vector.NormalizeObservation).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "pixelgym/envs/vector/vector_wrapper.h"
#include "pixelgym/wrappers/box_key.h"
#include "pixelgym/wrappers/running_statistics.h"

namespace pixelgym::vector {

/// Replaces each env's Box observation (the bare Box with key "", or the entry `key` of a Dict;
/// other keys pass through) by (x - mean) / sqrt(var + epsilon), element by element, as float32,
/// where mean and var are one set of running statistics (wrappers::RunningStatistics: Gymnasium's
/// RunningMeanStd, from mean 0, var 1, count 1e-4) shared by every env. The single observation
/// space's entry becomes Box(-inf, inf) float32 of the same shape, and the batched space its
/// batch. Any Box dtype but bool is accepted.
///
/// Each call first merges the observations it returns into the statistics as one batch
/// (RunningStatistics::update_batch: Gymnasium's RunningMeanStd.update with a batch), then
/// normalizes them with the updated statistics:
/// - reset(): every env's reset observation; reset with a mask: only the masked envs' (the other
///   rows keep their last normalized observation, as the inner env keeps their last observation;
///   Gymnasium's wrapper refuses partial resets instead);
/// - step(): every row (under NextStep a row may be an env's reset observation: it counts, as
///   reset observations do), and under SameStep the rows of infos["final_obs"] too: the episode's
///   last observations are observations the envs returned, which under NextStep would be rows of
///   the batch. So the statistics see every observation each env produced, once, in every
///   autoreset mode, as the per-env wrapper would. infos["final_obs"] is replaced by this
///   wrapper's own batch, laid out as observation_space(): the ended envs' rows normalized with
///   the same statistics as this step's observations, the others zero ("_final_obs" says which).
///   (Gymnasium's wrapper refuses SameStep.)
/// Under NextStep and Disabled a batch of one env gives exactly (bit for bit) the per-env
/// wrapper's observations and statistics; under SameStep an ended env's last and reset
/// observations are merged as one batch of two (the per-env wrapper merges them one at a time):
/// the statistics agree up to rounding, and the last observation is normalized with statistics
/// that already include the reset one.
///
/// `set_update_statistics(false)` freezes the statistics (for evaluation); `statistics()` /
/// `set_statistics()` read and write them (RunningStatistics::to_value / from_value give the
/// checkpoint form). Allocates nothing per step beyond copying non-empty infos (VectorWrapper).
class NormalizeObservation final : public VectorWrapper {
 public:
  /// Throws std::invalid_argument as wrappers::find_box when `key` does not name a Box of the
  /// single observation space (empty `key`: the space itself must be a Box), for a bool Box, and
  /// unless epsilon is finite and > 0.
  explicit NormalizeObservation(std::unique_ptr<VectorEnv> env, const std::string& key = "",
                                double epsilon = 1e-8);

  /// The Dict key normalized; empty for a bare Box.
  const std::string& key() const { return where_.key; }
  /// The constant added to the variance before its square root.
  double epsilon() const { return epsilon_; }

  /// Whether observations update the statistics (true at construction).
  bool update_statistics() const { return update_statistics_; }
  /// false freezes the statistics (observations are still normalized with them); true resumes.
  void set_update_statistics(bool update) { update_statistics_ = update; }

  /// The current statistics, one entry per element of one env's Box (row-major).
  const wrappers::RunningStatistics& statistics() const { return statistics_; }
  /// Replaces the statistics (restoring a checkpoint). Throws std::invalid_argument naming the
  /// wrapper when they do not fit (RunningStatistics::invalid_reason); nothing changes then.
  void set_statistics(wrappers::RunningStatistics statistics);

 protected:
  std::string type_name() const override { return "NormalizeObservation"; }
  const VectorResetResult& do_reset(std::optional<std::uint64_t> seed, const Options& options,
                                    const Array* reset_mask) override;
  const VectorStepResult& do_step(const Value& actions) override;

 private:
  // Merges (when updating) and normalizes the rows of `in` (the inner env's batch) whose
  // `in_mask` entry is true (all when null) into the same rows of `out`, and the rows of
  // `final_in` whose `final_mask` entry is true into `final_out` (zeroing its other rows), when
  // `final_in` is not null.
  void transform(const Array& in, const bool* in_mask, Array& out, const Array* final_in,
                 const bool* final_mask, Array* final_out);

  wrappers::BoxKey where_;
  double epsilon_;
  bool update_statistics_ = true;
  wrappers::RunningStatistics statistics_;
  std::size_t row_size_;  // elements of one env's Box

  Value obs_;        // laid out as observation_space(); the results' obs
  Value final_obs_;  // SameStep: infos["final_obs"] normalized
  VectorResetResult reset_result_;
  VectorStepResult step_result_;
  std::vector<const void*> rows_;  // the rows merged by one call (capacity 2 num_envs)
};

}  // namespace pixelgym::vector
