// vector::RecordEpisodeStatistics: each env's episode return, length and wall time, in infos at
// the step its episode ends (gymnasium.wrappers.vector.RecordEpisodeStatistics, Gymnasium 1.x).
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "pixelgym/envs/vector/vector_wrapper.h"

namespace pixelgym::vector {

/// Accumulates each env's episode return (the sum of its rewards as the inner vector env returns
/// them), length (steps) and wall time, and on a step that ends episodes (terminated or
/// truncated) adds to infos
///   infos[stats_key] = Dict{"r": float64 (num_envs,), "l": int64 (num_envs,),
///                           "t": float64 (num_envs,)},  infos["_" + stats_key]: bool (num_envs,)
/// with the episode's values in the rows of the envs that ended it and 0 in the others, the mask
/// true for those rows (batched as VectorEnv batches infos). "t" is seconds since the episode
/// began, from std::chrono::steady_clock, as measured (Gymnasium rounds it to microseconds).
/// The last `buffer_length` episodes are kept, oldest first, episodes that end in the same step in
/// env order (Gymnasium's return_queue, length_queue, time_queue).
///
/// Which steps count, by autoreset mode (as Gymnasium's vector wrapper since its SameStep fix,
/// Farama-Foundation/Gymnasium#1624, after 1.3.0; releases up to 1.3.0 count SameStep as
/// NextStep, which drops the first step of every episode after an env's first):
/// - NextStep: the step after the one that ended env i's episode is env i's reset (reward 0,
///   both flags false, its action ignored): it belongs to no episode. Env i's counters restart
///   there (return 0, length 0, clock restarted), and its next episode's first step is the step
///   after it. So "l" is the number of steps the env really took, as the per-env wrapper counts.
/// - SameStep: the step that ends env i's episode also resets it: its reward and step count go
///   to the episode that ends, and the counters restart at once for the next step.
/// - Disabled: the caller resets ended envs with reset(seed, options, reset_mask); that reset
///   restarts the counters of the envs in the mask only (the others keep counting).
/// reset() without a mask restarts every env's counters.
///
/// Put it inside NormalizeReward to record raw returns (outside, the returns are normalized ones).
///
/// Allocations: a step that ends no episode allocates nothing (beyond copying infos the inner env
/// returned, when it returned any: see VectorWrapper); a step that ends one allocates the info
/// arrays (fresh ones, so that infos kept from an earlier step stay unchanged) and the queue's
/// entry. Throws std::runtime_error naming the key when the inner env's infos already hold
/// stats_key or "_" + stats_key (a per-env RecordEpisodeStatistics given to make_vec does: give
/// one of them another stats_key); this wrapper's counters have counted that step then.
class RecordEpisodeStatistics final : public VectorWrapper {
 public:
  /// Throws std::invalid_argument unless buffer_length >= 1 and stats_key is not empty.
  explicit RecordEpisodeStatistics(std::unique_ptr<VectorEnv> env, std::int64_t buffer_length = 100,
                                   const std::string& stats_key = "episode");

  /// How many finished episodes the queues keep.
  std::int64_t buffer_length() const { return buffer_length_; }
  /// The infos key the statistics go under (their mask under "_" + stats_key).
  const std::string& stats_key() const { return stats_key_; }
  /// Episodes ended so far, across every env.
  std::int64_t episode_count() const { return episode_count_; }
  /// Each env's current episode return and length so far (num_envs entries). Under NextStep an
  /// env whose episode ended at the last step still shows that episode's (until its reset step).
  const std::vector<double>& episode_returns() const { return returns_; }
  const std::vector<std::int64_t>& episode_lengths() const { return lengths_; }

  /// The last min(episode_count(), buffer_length) episodes' returns, lengths and wall times in
  /// seconds, oldest first, as new vectors.
  std::vector<double> return_queue() const;
  std::vector<std::int64_t> length_queue() const;
  std::vector<double> time_queue() const;

 protected:
  std::string type_name() const override { return "RecordEpisodeStatistics"; }
  const VectorResetResult& do_reset(std::optional<std::uint64_t> seed, const Options& options,
                                    const Array* reset_mask) override;
  const VectorStepResult& do_step(const Value& actions) override;

 private:
  using Clock = std::chrono::steady_clock;
  struct Episode {
    double r = 0.0;
    std::int64_t l = 0;
    double t = 0.0;
  };
  void restart(std::size_t i, Clock::time_point now);

  std::int64_t buffer_length_;
  std::string stats_key_;
  std::string mask_key_;  // "_" + stats_key_
  std::int64_t episode_count_ = 0;
  std::vector<double> returns_;
  std::vector<std::int64_t> lengths_;
  std::vector<Clock::time_point> starts_;
  std::vector<std::uint8_t> ended_;  // env i's episode ended at the last step
  std::deque<Episode> queue_;        // the last buffer_length_ episodes, oldest first
  VectorStepResult result_;
};

}  // namespace pixelgym::vector
