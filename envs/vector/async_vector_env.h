// AsyncVectorEnv: the envs stepped in parallel on a pool of worker threads
// (gymnasium.vector.AsyncVectorEnv, with threads instead of processes).
#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

#include "envs/vector/vector_env.h"

namespace pixelgym::vector {

/// A VectorEnv whose envs run on `num_threads()` worker threads, results written straight into
/// the shared batch buffers (each env into its own row, so workers never write the same bytes).
///
/// Pinning. Env i lives on worker i % num_threads() for its whole life: the worker builds it
/// (calls the factory), resets, steps and closes it, and destroys it. Why: an OSMesa context is
/// current on one thread at a time, and Mesa keeps a per-thread pointer to the current context
/// that outlives any switch. An env that moved between threads would leave its context current
/// on a thread it had left — a thread that, when it later made another context current, would
/// flush the first (a use after free once that env is destroyed elsewhere, a data race while it
/// renders on its new thread). Pinned, every context is created, made current, used and
/// destroyed by one thread, the renderer's make_current is a no-op check, and each Bullet world
/// stays in one core's cache. The cost is balance: with num_envs not a multiple of num_threads,
/// some workers run one env more per step (8 envs on 3 threads: 3, 3, 2).
///
/// Threads: `num_threads` 0 means min(num_envs, std::thread::hardware_concurrency()); more
/// threads than envs are clamped to num_envs (a thread without envs would only wait), not an
/// error. The calling thread only dispatches and batches infos; it waits while workers step.
///
/// Results are byte-identical to SyncVectorEnv's for the same seeds and actions, for any number
/// of threads: envs share nothing, and infos are batched on the calling thread in index order.
class AsyncVectorEnv final : public VectorEnv {
 public:
  /// Starts the workers and builds env i with `make_env(i)` on its worker (several at once:
  /// make_env must be thread-safe). Throws std::invalid_argument for num_envs < 1, num_threads
  /// < 0 or envs whose spaces differ, and what make_env throws, naming the env index (the envs
  /// built are destroyed and the workers stopped first).
  AsyncVectorEnv(int num_envs, const EnvFactory& make_env, int num_threads = 0,
                 AutoresetMode autoreset = AutoresetMode::kNextStep);
  /// Waits for a pending step, destroys the envs on their workers and stops the workers.
  ~AsyncVectorEnv() override;

  /// Validates and copies `actions` (the caller may reuse them at once), starts every env's
  /// step and returns without waiting. Throws as step() does before any env steps, and
  /// ResetNeeded when a step is already pending.
  void step_async(const Value& actions);
  /// Waits for the step begun by step_async and returns its batched results (as step()). Throws
  /// ResetNeeded without a pending step_async, and an env's error as step() does.
  const VectorStepResult& step_wait();

  /// Worker threads (after clamping).
  int num_threads() const { return static_cast<int>(threads_.size()); }

 protected:
  void start_all() override;
  void wait_all() override;

 private:
  void work(int worker, int stride);
  void stop() noexcept;

  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::condition_variable start_;
  std::condition_variable done_;
  std::uint64_t generation_ = 0;  // bumped by start_all; each worker runs once per value
  int running_ = 0;               // workers still running the current generation
  bool stopping_ = false;
};

}  // namespace pixelgym::vector
