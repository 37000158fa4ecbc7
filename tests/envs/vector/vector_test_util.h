// Helpers for the vector env tests: vector envs of ScriptedEnvs whose episodes end when a test
// says, and the ways to run them (sync, or a pool of 1, 2, 4 threads).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pixelgym/envs/vector/async_vector_env.h"
#include "pixelgym/envs/vector/sync_vector_env.h"
#include "pixelgym/envs/wrapper.h"
#include "tests/wrappers/scripted_env.h"

namespace pixelgym::testing {

/// Adds info to every call: {"t": int64 step count} on steps, {"seeded": bool} on resets.
class InfoWrapper final : public Wrapper {
 public:
  using Wrapper::Wrapper;

 protected:
  std::string type_name() const override { return "InfoWrapper"; }
  void do_reset(std::optional<std::uint64_t> seed, const Options& options,
                ResetResult& out) override {
    Wrapper::do_reset(seed, options, out);
    t_ = 0;
    out.info.insert("seeded", Array::scalar<bool>(seed.has_value()));
  }
  void do_step(const Value& action, StepResult& out) override {
    Wrapper::do_step(action, out);
    out.info.insert("t", Array::scalar<std::int64_t>(++t_));
  }

 private:
  std::int64_t t_ = 0;
};

/// How a test runs its vector env: 0 for SyncVectorEnv, else AsyncVectorEnv with that many
/// threads.
inline std::unique_ptr<vector::VectorEnv> make_vector_env(int threads, int num_envs,
                                                          const vector::EnvFactory& make_env,
                                                          vector::AutoresetMode mode) {
  if (threads == 0) return std::make_unique<vector::SyncVectorEnv>(num_envs, make_env, mode);
  return std::make_unique<vector::AsyncVectorEnv>(num_envs, make_env, threads, mode);
}

/// A vector env of ScriptedEnvs (observations: float32 (3,) noise; actions: float32 (1,) in
/// [-1, 1]; rewards 0.5, 0.25, 0.125, ... by step), env i's episodes `lengths[i]` steps long,
/// ending by truncation when `truncate`, each under an InfoWrapper. `scripted[i]` is env i's.
struct ScriptedVector {
  std::unique_ptr<vector::VectorEnv> env;
  std::vector<ScriptedEnv*> scripted;
};

inline ScriptedVector make_scripted_vector(const std::vector<int>& lengths, bool truncate,
                                           vector::AutoresetMode mode, int threads = 0) {
  ScriptedVector made;
  made.scripted.resize(lengths.size());
  const vector::EnvFactory factory = [&](int i) {
    auto env = std::make_unique<ScriptedEnv>(box(-10.0, 10.0, {3}), box(-1.0, 1.0, {1}),
                                             lengths[static_cast<std::size_t>(i)], truncate);
    env->rewards = {0.5, 0.25, 0.125, 0.0625, 0.03125};
    made.scripted[static_cast<std::size_t>(i)] = env.get();
    return std::make_unique<InfoWrapper>(std::move(env));
  };
  made.env = make_vector_env(threads, static_cast<int>(lengths.size()), factory, mode);
  return made;
}

/// A float32 (n, 1) batch of actions, env i's `base + 0.01 i`.
inline Value scripted_actions(int n, float base) {
  std::vector<float> values;
  for (int i = 0; i < n; ++i) values.push_back(base + 0.01F * static_cast<float>(i));
  return Array::from_vector<float>({n, 1}, values);
}

}  // namespace pixelgym::testing
