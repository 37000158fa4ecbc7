#include "pixelgym/wrappers/record_episode_statistics.h"

#include <stdexcept>
#include <utility>

namespace pixelgym::wrappers {

RecordEpisodeStatistics::RecordEpisodeStatistics(std::unique_ptr<Env> env,
                                                 std::int64_t buffer_length,
                                                 const std::string& stats_key)
    : Wrapper(std::move(env)), buffer_length_(buffer_length), stats_key_(stats_key) {
  if (buffer_length < 1) {
    throw std::invalid_argument("RecordEpisodeStatistics: buffer_length must be >= 1, got " +
                                std::to_string(buffer_length));
  }
  if (stats_key.empty()) {
    throw std::invalid_argument("RecordEpisodeStatistics: stats_key must not be empty");
  }
  ring_.reserve(static_cast<std::size_t>(buffer_length));
  start_ = std::chrono::steady_clock::now();
}

void RecordEpisodeStatistics::do_reset(std::optional<std::uint64_t> seed, const Options& options,
                                       ResetResult& out) {
  env_->reset_into(out, seed, options);
  return_ = 0.0;
  length_ = 0;
  start_ = std::chrono::steady_clock::now();
}

void RecordEpisodeStatistics::do_step(const Value& action, StepResult& out) {
  env_->step_into(action, out);
  return_ += out.reward;
  ++length_;
  if (!out.terminated && !out.truncated) return;
  const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start_;
  if (out.info.contains(stats_key_)) {
    throw std::runtime_error("RecordEpisodeStatistics: info already holds \"" + stats_key_ +
                             "\" from " + env_->name() + "; give another stats_key");
  }
  const Episode episode{return_, length_, elapsed.count()};
  out.info.insert(stats_key_, ValueDict{{"r", Array::scalar<double>(episode.r)},
                                        {"l", Array::scalar<std::int64_t>(episode.l)},
                                        {"t", Array::scalar<double>(episode.t)}});
  if (ring_.size() < static_cast<std::size_t>(buffer_length_)) {
    ring_.push_back(episode);
  } else {
    ring_[static_cast<std::size_t>(episode_count_ % buffer_length_)] = episode;
  }
  ++episode_count_;
}

template <typename T, typename Field>
std::vector<T> RecordEpisodeStatistics::queue(Field field) const {
  std::vector<T> values;
  values.reserve(ring_.size());
  // Once the ring is full, the oldest episode sits where the next one will go.
  const std::size_t first = ring_.size() < static_cast<std::size_t>(buffer_length_)
                                ? 0
                                : static_cast<std::size_t>(episode_count_ % buffer_length_);
  for (std::size_t i = 0; i < ring_.size(); ++i) {
    values.push_back(field(ring_[(first + i) % ring_.size()]));
  }
  return values;
}

std::vector<double> RecordEpisodeStatistics::return_queue() const {
  return queue<double>([](const Episode& episode) { return episode.r; });
}

std::vector<std::int64_t> RecordEpisodeStatistics::length_queue() const {
  return queue<std::int64_t>([](const Episode& episode) { return episode.l; });
}

std::vector<double> RecordEpisodeStatistics::time_queue() const {
  return queue<double>([](const Episode& episode) { return episode.t; });
}

}  // namespace pixelgym::wrappers
