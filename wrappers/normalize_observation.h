// NormalizeObservation: normalizes a Box observation (or one Dict key) with running statistics
// (gymnasium.wrappers.NormalizeObservation), with statistics that can be frozen and checkpointed.
#pragma once

#include <memory>
#include <string>

#include "pixelgym/envs/wrapper.h"
#include "pixelgym/wrappers/box_key.h"
#include "pixelgym/wrappers/running_statistics.h"

namespace pixelgym::wrappers {

/// Replaces the Box observation (a bare Box with key "", or the entry `key` of a Dict; other keys
/// pass through untouched) by (x - mean) / sqrt(var + epsilon), element by element, as float32;
/// that entry's space becomes Box(-inf, inf) float32 of the same shape. Any Box dtype is
/// accepted (a uint8 image, int32 counters, float64 state).
///
/// mean and var are running statistics of every observation seen, reset observations included,
/// as in Gymnasium 1.x: each observation first updates them (RunningStatistics: Gymnasium's
/// RunningMeanStd, starting from mean 0, var 1, count 1e-4), then is normalized with the updated
/// values. `set_update_statistics(false)` freezes them (for evaluation: the same statistics
/// normalize, nothing updates them); `statistics()` / `set_statistics()` read and write them
/// (RunningStatistics::to_value / from_value give the checkpoint form). Allocates nothing per
/// step.
class NormalizeObservation final : public ObservationWrapper {
 public:
  /// Throws std::invalid_argument as find_box when `key` does not name a Box (empty `key`: the
  /// observation space itself must be a Box), and unless epsilon is finite and > 0.
  explicit NormalizeObservation(std::unique_ptr<Env> env, const std::string& key = "",
                                double epsilon = 1e-8);

  /// The Dict key normalized; empty for a bare Box.
  const std::string& key() const { return where_.key; }
  /// The constant added to the variance before its square root.
  double epsilon() const { return epsilon_; }

  /// Whether observations update the statistics (true at construction).
  bool update_statistics() const { return update_statistics_; }
  /// false freezes the statistics (observations are still normalized with them); true resumes.
  void set_update_statistics(bool update) { update_statistics_ = update; }

  /// The current statistics, one entry per element of the normalized Box (row-major).
  const RunningStatistics& statistics() const { return statistics_; }
  /// Replaces the statistics (restoring a checkpoint). Throws std::invalid_argument naming the
  /// wrapper when they do not fit (RunningStatistics::invalid_reason); nothing changes then.
  void set_statistics(RunningStatistics statistics);

 protected:
  std::string type_name() const override { return "NormalizeObservation"; }
  void observation(const Value& in, Value& out) override;

 private:
  BoxKey where_;
  double epsilon_;
  bool update_statistics_ = true;
  RunningStatistics statistics_;
};

}  // namespace pixelgym::wrappers
