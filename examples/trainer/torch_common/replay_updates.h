// When an off-policy learner updates, and what its updates cost: updates_per_env_step updates per
// env step once the seed steps are done (the fraction carried over as credit), each from a batch
// sampled from the replay buffer, and the metrics every replay learner reports about them.
// Torch-free; shared by DrQ and DrQ-v2.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <random>
#include <string>
#include <utility>

#include "examples/trainer/torch_common/replay_buffer.h"
#include "pixelgym/trainer/algorithm.h"
#include "pixelgym/trainer/progress_csv.h"
#include "pixelgym/trainer/stepped_algorithm.h"

namespace pixelgym::trainer {

/// sum / count, or ProgressRow::kNone (an empty progress.csv field) when count is 0.
inline double mean_or_none(double sum, std::int64_t count) {
  return count > 0 ? sum / static_cast<double>(count) : ProgressRow::kNone;
}

class ReplayUpdates {
 public:
  /// `num_envs` envs stepped together, `per_env_step` updates per env step (> 0), none before
  /// `seed_env_steps` env steps.
  ReplayUpdates(std::int64_t num_envs, double per_env_step, std::int64_t seed_env_steps)
      : num_envs_(num_envs), per_env_step_(per_env_step), seed_env_steps_(seed_env_steps) {}

  /// Makes the updates due after an env step, `env_steps` into the run: for each, samples
  /// `batch_size` transitions of `buffer` into `batch` with `rng` and calls `update(batch)`,
  /// then asks `stop` (when set); returns true when it answered true (the updates not made stay
  /// as credit).
  template <typename Update>
  bool run(std::int64_t env_steps, const ReplayBuffer& buffer, std::int64_t batch_size,
           std::mt19937_64& rng, ReplayBatch& batch, const StopCheck& stop, Update&& update) {
    if (env_steps < seed_env_steps_ || !buffer.can_sample()) return false;
    credit_ += static_cast<double>(num_envs_) * per_env_step_;
    while (credit_ >= 1.0) {
      credit_ -= 1.0;
      auto start = Clock::now();
      buffer.sample(batch_size, rng, batch);
      sample_s_ += seconds_since(start);
      start = Clock::now();
      update(static_cast<const ReplayBatch&>(batch));
      update_s_ += seconds_since(start);
      ++iteration_updates_;
      ++total_;
      if (stop && stop(env_steps)) return true;
    }
    return false;
  }

  /// The updates of the iteration that ends now (the count the learner's means divide by).
  std::int64_t iteration_updates() const { return iteration_updates_; }
  /// Adds the replay metrics of the iteration that ends now to `metrics` — gradient_updates
  /// (all so far), updates_per_s, replay_transitions, replay_mb, env_s, act_s, sample_s,
  /// update_s — and starts the next iteration's.
  void end_iteration(const ReplayBuffer& buffer, const LoopTimes& times,
                     std::map<std::string, double>& metrics) {
    const double seconds = sample_s_ + update_s_;
    metrics["gradient_updates"] = static_cast<double>(total_);
    metrics["updates_per_s"] = iteration_updates_ > 0
                                   ? static_cast<double>(iteration_updates_) / seconds
                                   : ProgressRow::kNone;
    metrics["replay_transitions"] = static_cast<double>(buffer.steps_added());
    metrics["replay_mb"] = static_cast<double>(buffer.bytes()) / 1e6;
    metrics["env_s"] = times.env;
    metrics["act_s"] = times.act;
    metrics["sample_s"] = std::exchange(sample_s_, 0.0);
    metrics["update_s"] = std::exchange(update_s_, 0.0);
    iteration_updates_ = 0;
  }
  /// The replay metrics' names, in progress.csv's order.
  static std::vector<std::string> metric_names() {
    return {"gradient_updates", "updates_per_s", "replay_transitions",
            "replay_mb",        "env_s",         "act_s",
            "sample_s",         "update_s"};
  }

  /// For checkpoints: the credit carried over and the updates made so far.
  double credit() const { return credit_; }
  std::int64_t total() const { return total_; }
  void restore(double credit, std::int64_t total) {
    credit_ = credit;
    total_ = total;
  }

 private:
  using Clock = std::chrono::steady_clock;
  static double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
  }

  std::int64_t num_envs_;
  double per_env_step_;
  std::int64_t seed_env_steps_;
  double credit_ = 0.0;
  std::int64_t total_ = 0;
  std::int64_t iteration_updates_ = 0;
  double sample_s_ = 0.0, update_s_ = 0.0;
};

}  // namespace pixelgym::trainer
