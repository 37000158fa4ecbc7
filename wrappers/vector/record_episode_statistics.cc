#include "pixelgym/wrappers/vector/record_episode_statistics.h"

#include <optional>
#include <stdexcept>
#include <utility>

namespace pixelgym::vector {

RecordEpisodeStatistics::RecordEpisodeStatistics(std::unique_ptr<VectorEnv> env,
                                                 std::int64_t buffer_length,
                                                 const std::string& stats_key)
    : VectorWrapper(std::move(env)),
      buffer_length_(buffer_length),
      stats_key_(stats_key),
      mask_key_("_" + stats_key) {
  if (buffer_length < 1) {
    throw std::invalid_argument("RecordEpisodeStatistics: buffer_length must be >= 1, got " +
                                std::to_string(buffer_length));
  }
  if (stats_key.empty()) {
    throw std::invalid_argument("RecordEpisodeStatistics: stats_key must not be empty");
  }
  const auto n = static_cast<std::size_t>(num_envs());
  returns_.assign(n, 0.0);
  lengths_.assign(n, 0);
  starts_.assign(n, Clock::now());
  ended_.assign(n, 0);
}

void RecordEpisodeStatistics::restart(std::size_t i, Clock::time_point now) {
  returns_[i] = 0.0;
  lengths_[i] = 0;
  starts_[i] = now;
  ended_[i] = 0;
}

const VectorResetResult& RecordEpisodeStatistics::do_reset(std::optional<std::uint64_t> seed,
                                                           const Options& options,
                                                           const Array* reset_mask) {
  const VectorResetResult& result = reset_inner(seed, options, reset_mask);
  const Clock::time_point now = Clock::now();
  for (std::size_t i = 0; i < returns_.size(); ++i) {
    if (reset_mask == nullptr || reset_mask->data<bool>()[i]) restart(i, now);
  }
  return result;
}

const VectorStepResult& RecordEpisodeStatistics::do_step(const Value& actions) {
  const VectorStepResult& inner = step_inner(actions);
  forward(inner, result_);
  const std::size_t n = returns_.size();
  const double* rewards = inner.rewards.data<double>();
  const bool* terminated = inner.terminated.data<bool>();
  const bool* truncated = inner.truncated.data<bool>();
  const bool same_step = autoreset_mode() == AutoresetMode::kSameStep;

  // The clock is read only when an episode starts or ends.
  std::optional<Clock::time_point> now;
  const auto clock = [&now] {
    if (!now) now = Clock::now();
    return *now;
  };
  bool any_ended = false;
  for (std::size_t i = 0; i < n; ++i) {
    if (!same_step && ended_[i] != 0) {
      // NextStep: this step was env i's reset. (Disabled never gets here: the inner env refuses
      // a step before the caller's reset, which restarts the counters.)
      restart(i, clock());
      continue;
    }
    returns_[i] += rewards[i];
    ++lengths_[i];
    ended_[i] = terminated[i] || truncated[i] ? 1 : 0;
    any_ended = any_ended || ended_[i] != 0;
  }
  if (!any_ended) return result_;

  Info& infos = result_.infos;
  if (infos.contains(stats_key_) || infos.contains(mask_key_)) {
    throw std::runtime_error("RecordEpisodeStatistics: infos already hold \"" +
                             (infos.contains(stats_key_) ? stats_key_ : mask_key_) + "\" from " +
                             this->inner().name() + "; give another stats_key");
  }
  const auto count = static_cast<std::int64_t>(n);
  Array r(DType::kFloat64, {count});
  Array l(DType::kInt64, {count});
  Array t(DType::kFloat64, {count});
  Array mask(DType::kBool, {count});
  const Clock::time_point end = clock();
  for (std::size_t i = 0; i < n; ++i) {
    if (ended_[i] == 0) continue;
    const std::chrono::duration<double> elapsed = end - starts_[i];
    const Episode episode{returns_[i], lengths_[i], elapsed.count()};
    r.data<double>()[i] = episode.r;
    l.data<std::int64_t>()[i] = episode.l;
    t.data<double>()[i] = episode.t;
    mask.data<bool>()[i] = true;
    queue_.push_back(episode);
    if (queue_.size() > static_cast<std::size_t>(buffer_length_)) queue_.pop_front();
    ++episode_count_;
    if (same_step) restart(i, end);
  }
  infos.insert(stats_key_,
               ValueDict{{"r", std::move(r)}, {"l", std::move(l)}, {"t", std::move(t)}});
  infos.insert(mask_key_, std::move(mask));
  return result_;
}

std::vector<double> RecordEpisodeStatistics::return_queue() const {
  std::vector<double> values;
  for (const Episode& episode : queue_) values.push_back(episode.r);
  return values;
}

std::vector<std::int64_t> RecordEpisodeStatistics::length_queue() const {
  std::vector<std::int64_t> values;
  for (const Episode& episode : queue_) values.push_back(episode.l);
  return values;
}

std::vector<double> RecordEpisodeStatistics::time_queue() const {
  std::vector<double> values;
  for (const Episode& episode : queue_) values.push_back(episode.t);
  return values;
}

}  // namespace pixelgym::vector
