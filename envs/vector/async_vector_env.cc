#include "pixelgym/envs/vector/async_vector_env.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "pixelgym/envs/vector/worker_threads.h"

namespace pixelgym::vector {
namespace {

// How long a thread waiting for work, or for the other threads, spins before it sleeps.
constexpr std::chrono::microseconds kSpin{200};

int clamp_threads(int num_envs, int num_threads) {
  if (num_threads < 0) {
    throw std::invalid_argument("AsyncVectorEnv: num_threads must be >= 0 (0: one per core), got " +
                                std::to_string(num_threads));
  }
  if (num_threads == 0) {
    num_threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  }
  return std::max(1, std::min(num_threads, num_envs));
}

void pause() {
#if defined(__x86_64__) || defined(__i386__)
  _mm_pause();
#else
  std::this_thread::yield();
#endif
}

// Spins until `done()` or kSpin has passed; returns done().
template <typename Done>
bool spin_until(const Done& done) {
  const auto deadline = std::chrono::steady_clock::now() + kSpin;
  for (;;) {
    for (int k = 0; k < 64; ++k) {
      if (done()) return true;
      pause();
    }
    if (std::chrono::steady_clock::now() >= deadline) return done();
  }
}

}  // namespace

// One worker: its thread (one of WorkerThreads', for this vector env's life) and how it is handed
// calls.
struct AsyncVectorEnv::Worker {
  WorkerThreads::Task thread;
  // Bumped (under `mutex`) to hand the worker the current call.
  std::atomic<std::uint64_t> ticket{0};
  std::mutex mutex;
  std::condition_variable wake;
};

int AsyncVectorEnv::threads_for(int num_envs, int num_threads) {
  return clamp_threads(num_envs, num_threads);
}

AsyncVectorEnv::AsyncVectorEnv(int num_envs, const EnvFactory& make_env, int num_threads,
                               AutoresetMode autoreset)
    : BatchRunner("AsyncVectorEnv", num_envs, autoreset) {
  const int threads = clamp_threads(num_envs, num_threads);
  spin_ = threads <= static_cast<int>(std::thread::hardware_concurrency());
  for (int w = 0; w < threads; ++w) workers_.push_back(std::make_unique<Worker>());
  try {
    for (int w = 0; w < threads; ++w) {
      workers_[w]->thread = WorkerThreads::start(w, [this, w] { work(w); });
    }
    build(make_env);
  } catch (...) {
    stop();
    throw;
  }
}

AsyncVectorEnv::~AsyncVectorEnv() {
  if (step_pending()) wait_all();
  destroy_envs();
  stop();
}

void AsyncVectorEnv::stop() noexcept {
  stopping_.store(true, std::memory_order_release);
  for (auto& worker : workers_) {
    { const std::lock_guard<std::mutex> lock(worker->mutex); }
    worker->wake.notify_one();
  }
  for (auto& worker : workers_) {
    if (worker->thread.joinable()) worker->thread.join();
  }
}

void AsyncVectorEnv::work(int index) {
  Worker& worker = *workers_[static_cast<std::size_t>(index)];
  std::uint64_t seen = 0;
  const auto handed = [&] {
    return stopping_.load(std::memory_order_acquire) ||
           worker.ticket.load(std::memory_order_acquire) != seen;
  };
  for (;;) {
    if (!(spin_ && spin_until(handed))) {
      std::unique_lock<std::mutex> lock(worker.mutex);
      worker.wake.wait(lock, handed);
    }
    if (stopping_.load(std::memory_order_acquire)) return;
    seen = worker.ticket.load(std::memory_order_acquire);
    run_share(index);
    if (running_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
      const std::lock_guard<std::mutex> lock(done_mutex_);
      done_.notify_one();
    }
  }
}

void AsyncVectorEnv::run_share(int worker) {
  for (int i = worker; i < num_envs(); i += num_threads()) run_env(i);
}

void AsyncVectorEnv::hand(int first_worker) {
  running_.store(num_threads() - first_worker, std::memory_order_relaxed);
  for (int w = first_worker; w < num_threads(); ++w) {
    Worker& worker = *workers_[static_cast<std::size_t>(w)];
    {
      // Under the mutex, so that a worker about to sleep either sees the new ticket or is woken.
      const std::lock_guard<std::mutex> lock(worker.mutex);
      worker.ticket.fetch_add(1, std::memory_order_release);
    }
    worker.wake.notify_one();
  }
}

void AsyncVectorEnv::start_all() { hand(0); }

void AsyncVectorEnv::run_all() {
  hand(1);
  run_share(0);
  wait_all();
}

void AsyncVectorEnv::wait_all() {
  const auto finished = [this] { return running_.load(std::memory_order_acquire) == 0; };
  if (spin_ && spin_until(finished)) return;
  std::unique_lock<std::mutex> lock(done_mutex_);
  done_.wait(lock, finished);
}

void AsyncVectorEnv::step_async(const Value& actions) {
  begin_step(actions, "step_async()", false);
}

const VectorStepResult& AsyncVectorEnv::step_wait() { return end_step("step_wait()"); }

}  // namespace pixelgym::vector
