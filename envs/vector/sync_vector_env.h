// SyncVectorEnv: the envs stepped one after the other on the calling thread
// (gymnasium.vector.SyncVectorEnv).
#pragma once

#include <memory>
#include <vector>

#include "envs/vector/vector_env.h"

namespace pixelgym::vector {

/// A VectorEnv that runs its envs in a loop on the calling thread, in index order: no threads, no
/// synchronization, the reference the thread pool is tested against (byte-identical results).
/// The envs draw with one shared GL context (see VectorEnv: GL contexts) unless
/// `share_gl_contexts` is false; a context is made current on the calling thread while an env
/// renders.
class SyncVectorEnv final : public VectorEnv {
 public:
  /// Builds env i with `make_env(i)` for i in [0, num_envs). Throws std::invalid_argument for
  /// num_envs < 1 or envs whose spaces differ, and what make_env throws, naming the env index.
  SyncVectorEnv(int num_envs, const EnvFactory& make_env,
                AutoresetMode autoreset = AutoresetMode::kNextStep, bool share_gl_contexts = true);
  /// Takes envs built already (env i is `envs[i]`; those that rendered already keep their own
  /// contexts). Throws as above.
  explicit SyncVectorEnv(std::vector<std::unique_ptr<Env>> envs,
                         AutoresetMode autoreset = AutoresetMode::kNextStep,
                         bool share_gl_contexts = true);
  ~SyncVectorEnv() override;

 protected:
  void start_all() override;
  void wait_all() override {}
};

}  // namespace pixelgym::vector
