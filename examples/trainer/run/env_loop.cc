#include "pixelgym/trainer/env_loop.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "pixelgym/envs/vector/vector_wrapper.h"
#include "pixelgym/trainer/communicator.h"

namespace pixelgym::trainer {

std::uint64_t env_digest(const Value& observations, const std::vector<double>& episode_returns,
                         const std::vector<std::int64_t>& episode_lengths) {
  std::uint64_t digest = fnv1a(nullptr, 0);
  const auto add_array = [&digest](const std::string& key, const Array& array) {
    digest = fnv1a(key.data(), key.size(), digest);
    digest = fnv1a(array.raw_data(), array.nbytes(), digest);
  };
  if (observations.is_array()) {
    add_array("", observations.array());
  } else if (observations.is_dict()) {
    const ValueDict& dict = observations.dict();
    std::vector<std::size_t> order(dict.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(),
              [&dict](std::size_t a, std::size_t b) { return dict.keys()[a] < dict.keys()[b]; });
    for (const std::size_t i : order) {
      if (!dict.values()[i].is_array()) {
        throw std::invalid_argument("env_digest: observation key \"" + dict.keys()[i] +
                                    "\" must be an Array, got " + dict.values()[i].kind());
      }
      add_array(dict.keys()[i], dict.values()[i].array());
    }
  } else {
    throw std::invalid_argument(
        "env_digest: expected observations of an Array or a Dict of "
        "Arrays, got " +
        std::string(observations.kind()));
  }
  digest = fnv1a(episode_returns.data(), episode_returns.size() * sizeof(double), digest);
  digest = fnv1a(episode_lengths.data(), episode_lengths.size() * sizeof(std::int64_t), digest);
  return digest;
}

EnvLoop::EnvLoop(vector::VectorEnv& env, std::uint64_t seed, const std::string& episode_key)
    : env_(&env),
      episodes_(std::make_unique<vector::VectorWrapper>(env), 1, episode_key),
      batch_bytes_(env.action_space().zeros().array().nbytes()),
      episode_key_(episode_key),
      seed_(seed) {}

const Value& EnvLoop::reset() {
  observations_ = episodes_.reset(seed_).obs;
  started_ = true;
  return observations_;
}

const vector::VectorStepResult& EnvLoop::step(const Value& actions) {
  if (!started_) throw std::logic_error("EnvLoop::step before reset()");
  const Array& batch = actions.array();
  action_log_.append(static_cast<const char*>(batch.raw_data()), batch.nbytes());
  const vector::VectorStepResult& result = episodes_.step(actions);
  observations_ = result.obs;
  ++batches_;
  return result;
}

std::vector<EndedEpisode> EnvLoop::ended_episodes(const vector::VectorStepResult& step) const {
  std::vector<EndedEpisode> ended;
  const std::string mask_key = "_" + episode_key_;
  if (!step.infos.contains(mask_key)) return ended;
  const bool* mask = step.infos.at(mask_key).array().data<bool>();
  const ValueDict& stats = step.infos.at(episode_key_).dict();
  const double* returns = stats.at("r").array().data<double>();
  const std::int64_t* lengths = stats.at("l").array().data<std::int64_t>();
  for (std::int64_t e = 0; e < env_->num_envs(); ++e) {
    if (mask[e]) ended.push_back({returns[e], lengths[e]});
  }
  return ended;
}

std::vector<double> EnvLoop::ended_returns(const vector::VectorStepResult& step) const {
  std::vector<double> returns;
  for (const EndedEpisode& episode : ended_episodes(step))
    returns.push_back(episode.episode_return);
  return returns;
}

bool EnvLoop::action_log_covers(std::int64_t env_steps) const {
  return action_log_.size() ==
         static_cast<std::size_t>(env_steps / env_->num_envs()) * batch_bytes_;
}

void EnvLoop::replay(const std::string& log, std::int64_t env_steps,
                     const std::function<void(const Value& first_observations)>& on_reset,
                     const std::function<void(const Value& actions,
                                              const vector::VectorStepResult& step)>& on_step) {
  if (started_) throw std::logic_error("EnvLoop::replay: the envs were already reset or stepped");
  Value actions = zero_actions();
  Array& batch = actions.array();
  const std::size_t batch_bytes = batch_bytes_;
  const auto batches = static_cast<std::size_t>(env_steps / env_->num_envs());
  if (log.size() != batches * batch_bytes) {
    throw std::invalid_argument(
        "replay of the env actions: an action log of " + std::to_string(batches) + " batches of " +
        std::to_string(batch_bytes) + " bytes (for " + std::to_string(env_steps) +
        " env steps) expected, got " + std::to_string(log.size()) + " bytes");
  }
  on_reset(reset());
  for (std::size_t b = 0; b < batches; ++b) {
    std::memcpy(batch.raw_data(), log.data() + b * batch_bytes, batch_bytes);
    on_step(actions, step(actions));
  }
  action_log_ = log;
}

std::uint64_t EnvLoop::digest() const {
  if (!started_) return 0;
  return env_digest(observations_, episodes_.episode_returns(), episodes_.episode_lengths());
}

}  // namespace pixelgym::trainer
