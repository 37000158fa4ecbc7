// WorkerThreads: the process's parked threads that AsyncVectorEnv's workers run on, kept and
// reused from one vector env to the next instead of started and ended with each.
#pragma once

#include <functional>
#include <memory>

namespace pixelgym::vector {

/// Runs tasks on threads that outlive them: when a task returns, its thread parks, and the next
/// task started is given a parked thread before a new one is started. So making and closing
/// vector envs over and over reuses the same threads, and whatever a library keeps per thread is
/// kept once per thread, not once per vector env.
///
/// Why: a private copy of Mesa (render/mesa_copy.h) comes with a libc of its own, which never
/// learns that a thread ended (only the process's first libc runs thread exit). Its malloc keeps
/// a cache per thread (tcache: up to 7 freed blocks of each small size), so every thread that had
/// drawn with a private copy and ended left that cache behind for good: about 0.15 MB per worker
/// thread each time a vector env was made and closed (docs/design-notes.md, "Vector envs").
///
/// A task started for `slot` gets, when one is parked, the thread that last ran a task for the
/// same slot (AsyncVectorEnv's slot is the worker index, and worker w draws with copy w of Mesa:
/// so a thread keeps drawing with one copy, and holds one such cache, not one per copy).
///
/// Parked threads wait on a condition variable (no CPU) until the process ends; there are never
/// more of them than the most tasks that ran at once. A child process made by fork() starts with
/// none (the parent's are not in it).
class WorkerThreads {
 public:
  /// One task running on a worker thread. Its destructor waits for the task to return.
  class Task {
   public:
    Task();
    ~Task();
    Task(Task&&) noexcept;
    Task& operator=(Task&&) noexcept;

    /// Whether it runs a task not yet waited for.
    bool joinable() const;
    /// Waits until the task has returned (and its thread is parked); a no-op when not joinable.
    void join();

    /// The thread a task runs on (opaque).
    struct Thread;

   private:
    friend class WorkerThreads;
    explicit Task(Thread* thread);
    Thread* thread_ = nullptr;
  };

  /// Runs `task` on a parked thread (preferring the one that last ran `slot`) or on a new one.
  /// `task` must not throw (an exception leaving it ends the process, as with std::thread).
  /// Throws std::system_error when no thread can be started.
  static Task start(int slot, std::function<void()> task);

  /// Threads started so far in this process (parked or running), for tests.
  static int threads_started();
};

}  // namespace pixelgym::vector
