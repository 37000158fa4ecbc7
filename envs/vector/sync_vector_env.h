// SyncVectorEnv: the envs stepped one after the other on the calling thread
// (gymnasium.vector.SyncVectorEnv).
#pragma once

#include <memory>
#include <vector>

#include "pixelgym/envs/vector/batch_runner.h"

namespace pixelgym::vector {

/// A BatchRunner that runs its envs in a loop on the calling thread, in index order: no threads,
/// no synchronization, the reference the thread pool is tested against (byte-identical results).
class SyncVectorEnv final : public BatchRunner {
 public:
  /// Builds env i with `make_env(i)` for i in [0, num_envs). Throws std::invalid_argument for
  /// num_envs < 1 or envs whose spaces differ, and what make_env throws, naming the env index.
  SyncVectorEnv(int num_envs, const EnvFactory& make_env,
                AutoresetMode autoreset = AutoresetMode::kNextStep);
  /// Takes envs built already (env i is `envs[i]`). Throws as above.
  explicit SyncVectorEnv(std::vector<std::unique_ptr<Env>> envs,
                         AutoresetMode autoreset = AutoresetMode::kNextStep);
  /// Destroys the envs, without calling their close().
  ~SyncVectorEnv() override;

 protected:
  void start_all() override;
  void wait_all() override {}
};

}  // namespace pixelgym::vector
