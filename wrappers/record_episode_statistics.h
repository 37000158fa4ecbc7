// RecordEpisodeStatistics: puts each episode's return, length and wall time in info["episode"]
// at its last step (gymnasium.wrappers.RecordEpisodeStatistics).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pixelgym/envs/wrapper.h"

namespace pixelgym::wrappers {

/// On the step that ends an episode (terminated or truncated), adds
/// info[stats_key] = Dict{"r": float64 () the sum of the episode's rewards, "l": int64 () its
/// number of steps, "t": float64 () seconds of wall time since its reset} (Gymnasium rounds "t"
/// to microseconds; here it is kept as measured, from std::chrono::steady_clock). Rewards are
/// those the inner env returns (put this wrapper inside NormalizeReward to record raw returns).
/// The last `buffer_length` episodes' returns, lengths and times are kept, oldest first.
///
/// Nothing is allocated on the steps inside an episode; the step that ends one allocates the
/// small info Dict (fresh arrays, so that a caller keeping an earlier info sees it unchanged).
/// Throws std::runtime_error naming the key if the inner env already put stats_key in info.
class RecordEpisodeStatistics final : public Wrapper {
 public:
  /// Throws std::invalid_argument unless buffer_length >= 1 and stats_key is not empty.
  explicit RecordEpisodeStatistics(std::unique_ptr<Env> env, std::int64_t buffer_length = 100,
                                   const std::string& stats_key = "episode");

  /// How many finished episodes the queues keep.
  std::int64_t buffer_length() const { return buffer_length_; }
  /// The info key the statistics go under.
  const std::string& stats_key() const { return stats_key_; }
  /// Episodes ended so far (by terminated or truncated) through this wrapper.
  std::int64_t episode_count() const { return episode_count_; }
  /// The current episode's return so far.
  double episode_return() const { return return_; }
  /// The current episode's steps so far.
  std::int64_t episode_length() const { return length_; }

  /// The last min(episode_count(), buffer_length) episodes' returns, lengths and wall times in
  /// seconds, oldest first, as new vectors (Gymnasium's return_queue, length_queue and
  /// time_queue).
  std::vector<double> return_queue() const;
  std::vector<std::int64_t> length_queue() const;
  std::vector<double> time_queue() const;

 protected:
  std::string type_name() const override { return "RecordEpisodeStatistics"; }
  void do_reset(std::optional<std::uint64_t> seed, const Options& options,
                ResetResult& out) override;
  void do_step(const Value& action, StepResult& out) override;

 private:
  struct Episode {
    double r = 0.0;
    std::int64_t l = 0;
    double t = 0.0;
  };
  template <typename T, typename Field>
  std::vector<T> queue(Field field) const;

  std::int64_t buffer_length_;
  std::string stats_key_;
  std::int64_t episode_count_ = 0;
  double return_ = 0.0;
  std::int64_t length_ = 0;
  std::chrono::steady_clock::time_point start_;
  std::vector<Episode> ring_;  // buffer_length_ slots, reserved up front; episode i in i % size
};

}  // namespace pixelgym::wrappers
