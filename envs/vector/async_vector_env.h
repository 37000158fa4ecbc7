// AsyncVectorEnv: the envs stepped in parallel on a pool of worker threads
// (gymnasium.vector.AsyncVectorEnv, with threads instead of processes).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "pixelgym/envs/vector/batch_runner.h"

namespace pixelgym::vector {

/// A BatchRunner whose envs run on `num_threads()` threads, results written straight into the
/// shared batch buffers (each env into its own row, so threads never write the same bytes).
///
/// Threads. Env i belongs to worker i % num_threads() for its whole life: that worker builds it
/// (calls the factory), resets, steps, closes and destroys it; make_vec gives the envs of worker
/// w the rendering resources of worker w (see make_vec). Worker 0's envs run on the calling
/// thread in the calls that wait for the envs (the constructor, reset, step, close, the
/// destructor), since the caller would otherwise sit idle: step() with T threads keeps exactly T
/// threads busy, and with one thread it is a plain loop on the caller, as SyncVectorEnv. Only
/// step_async hands worker 0's envs to worker thread 0, so that the caller is free until
/// step_wait. So an env runs on one thread at a time, always the same one for workers 1..T-1,
/// and the caller or worker thread 0 (never both at once) for worker 0 (a pixel env binds its GL
/// context only for the length of each frame, render::Context, so it may move between threads).
/// The worker threads are WorkerThreads': parked when the vector env is destroyed and reused by
/// the next one (worker w gets the thread that last ran a worker w), so that making and closing
/// vector envs leaves nothing behind per thread (see WorkerThreads for what did).
///
/// Waiting. A worker done with a call, and the caller done with its share, first spin (pausing
/// the core) for up to 200 microseconds for the next call or the other threads, and only then
/// sleep on a condition variable; they spin only when the threads are no more than the cores
/// (spinning threads would otherwise take cores from those still working). Why: see
/// docs/design-notes.md, "Vector envs".
///
/// Threads: `num_threads` 0 means min(num_envs, std::thread::hardware_concurrency()); more
/// threads than envs are clamped to num_envs (a thread without envs would only wait), not an
/// error. With num_envs not a multiple of num_threads some threads run one env more per step
/// (8 envs on 3 threads: 3, 3, 2).
///
/// Results are byte-identical to SyncVectorEnv's for the same seeds and actions, for any number
/// of threads: the envs share nothing the runner gives them, and infos are batched on the
/// calling thread in index order.
class AsyncVectorEnv final : public BatchRunner {
 public:
  /// Starts the workers and builds env i with `make_env(i)` on its thread (several at once:
  /// make_env must be thread-safe). Throws std::invalid_argument for num_envs < 1, num_threads
  /// < 0 or envs whose spaces differ, and what make_env throws, naming the env index (the envs
  /// built are destroyed and the workers stopped first).
  AsyncVectorEnv(int num_envs, const EnvFactory& make_env, int num_threads = 0,
                 AutoresetMode autoreset = AutoresetMode::kNextStep);
  /// Waits for a pending step, destroys the envs on their threads and stops the workers.
  ~AsyncVectorEnv() override;

  /// Validates and copies `actions` (the caller may reuse them at once), starts every env's
  /// step on the worker threads and returns without waiting. Throws as step() does before any
  /// env steps, and ResetNeeded when a step is already pending.
  void step_async(const Value& actions);
  /// Waits for the step begun by step_async and returns its batched results (as step()). Throws
  /// ResetNeeded without a pending step_async, and an env's error as step() does.
  const VectorStepResult& step_wait();

  /// Threads that run envs, the caller's share included (after clamping).
  int num_threads() const { return static_cast<int>(workers_.size()); }
  /// The num_threads() an AsyncVectorEnv of `num_envs` envs asked for `num_threads` has (env i
  /// runs on worker i % that). Throws std::invalid_argument for num_threads < 0.
  static int threads_for(int num_envs, int num_threads);

 protected:
  void start_all() override;
  void wait_all() override;
  void run_all() override;

 private:
  struct Worker;
  void work(int worker);
  void hand(int first_worker);  // gives workers first_worker.. the current call
  void run_share(int worker);   // run_env for worker's envs
  void stop() noexcept;

  std::vector<std::unique_ptr<Worker>> workers_;
  bool spin_ = false;            // threads <= cores
  std::atomic<int> running_{0};  // workers still running the current call
  std::atomic<bool> stopping_{false};
  std::mutex done_mutex_;
  std::condition_variable done_;
};

}  // namespace pixelgym::vector
