#include "pixelgym/envs/vector/worker_threads.h"

#include <pthread.h>

#include <condition_variable>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

namespace pixelgym::vector {

// A worker thread: handed one task at a time, parked in between.
struct WorkerThreads::Task::Thread {
  std::mutex mutex;
  std::condition_variable handed;    // `task` set
  std::condition_variable finished;  // `done` set
  std::function<void()> task;
  bool has_task = false;
  bool done = true;
  int slot = -1;  // the slot of its latest task
};

namespace {

using Thread = WorkerThreads::Task::Thread;

struct Pool {
  std::mutex mutex;
  std::vector<std::unique_ptr<Thread>> all;  // every thread started, each lives until exit
  std::vector<Thread*> parked;
};

// Never destroyed: parked threads wait on their Thread until the process ends, past static
// destructors.
Pool*& pool() {
  static Pool* current = new Pool();
  return current;
}

void forget_parked_threads_in_child() {
  // The child has none of the parent's threads; the parent's pool (its mutex maybe held by a
  // thread that is not here) is left as it is.
  pool() = new Pool();
}

void run(Thread* self) {
  for (;;) {
    std::function<void()> task;
    {
      std::unique_lock<std::mutex> lock(self->mutex);
      self->handed.wait(lock, [self] { return self->has_task; });
      task = std::move(self->task);
      self->has_task = false;
    }
    task();
    task = nullptr;  // what it captured goes before the joiner returns
    Pool& threads = *pool();
    const std::lock_guard<std::mutex> pool_lock(threads.mutex);
    const std::lock_guard<std::mutex> lock(self->mutex);
    // Parked before the joiner hears of it: a vector env made right after this one's close gets
    // this thread, not a new one.
    threads.parked.push_back(self);
    self->done = true;
    self->finished.notify_all();
  }
}

}  // namespace

WorkerThreads::Task::Task() = default;
WorkerThreads::Task::Task(Thread* thread) : thread_(thread) {}
WorkerThreads::Task::~Task() { join(); }
WorkerThreads::Task::Task(Task&& other) noexcept : thread_(std::exchange(other.thread_, nullptr)) {}
WorkerThreads::Task& WorkerThreads::Task::operator=(Task&& other) noexcept {
  if (this != &other) {
    join();
    thread_ = std::exchange(other.thread_, nullptr);
  }
  return *this;
}

bool WorkerThreads::Task::joinable() const { return thread_ != nullptr; }

void WorkerThreads::Task::join() {
  if (thread_ == nullptr) return;
  std::unique_lock<std::mutex> lock(thread_->mutex);
  thread_->finished.wait(lock, [this] { return thread_->done; });
  lock.unlock();
  thread_ = nullptr;
}

WorkerThreads::Task WorkerThreads::start(int slot, std::function<void()> task) {
  static std::once_flag at_fork;
  std::call_once(at_fork,
                 [] { ::pthread_atfork(nullptr, nullptr, &forget_parked_threads_in_child); });
  Pool& threads = *pool();
  Thread* thread = nullptr;
  {
    const std::lock_guard<std::mutex> lock(threads.mutex);
    auto chosen = threads.parked.end();
    for (auto it = threads.parked.begin(); it != threads.parked.end(); ++it) {
      if ((*it)->slot == slot) {
        chosen = it;
        break;
      }
    }
    if (chosen == threads.parked.end() && !threads.parked.empty())
      chosen = threads.parked.end() - 1;
    if (chosen != threads.parked.end()) {
      thread = *chosen;
      threads.parked.erase(chosen);
    } else {
      threads.all.push_back(std::make_unique<Thread>());
      thread = threads.all.back().get();
      try {
        std::thread(run, thread).detach();
      } catch (...) {
        threads.all.pop_back();
        throw;
      }
    }
  }
  {
    const std::lock_guard<std::mutex> lock(thread->mutex);
    thread->task = std::move(task);
    thread->has_task = true;
    thread->done = false;
    thread->slot = slot;
  }
  thread->handed.notify_one();
  return Task(thread);
}

int WorkerThreads::threads_started() {
  Pool& threads = *pool();
  const std::lock_guard<std::mutex> lock(threads.mutex);
  return static_cast<int>(threads.all.size());
}

}  // namespace pixelgym::vector
