#include "envs/vector/async_vector_env.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace pixelgym::vector {
namespace {

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

}  // namespace

AsyncVectorEnv::AsyncVectorEnv(int num_envs, const EnvFactory& make_env, int num_threads,
                               AutoresetMode autoreset)
    : VectorEnv("AsyncVectorEnv", num_envs, autoreset) {
  const int threads = clamp_threads(num_envs, num_threads);
  try {
    for (int w = 0; w < threads; ++w)
      threads_.emplace_back([this, w, threads] { work(w, threads); });
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
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  start_.notify_all();
  for (std::thread& thread : threads_) {
    if (thread.joinable()) thread.join();
  }
}

void AsyncVectorEnv::work(int worker, int stride) {
  std::uint64_t seen = 0;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      start_.wait(lock, [&] { return stopping_ || generation_ != seen; });
      if (stopping_) return;
      seen = generation_;
    }
    for (int i = worker; i < num_envs(); i += stride) run_env(i);
    bool last = false;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      last = --running_ == 0;
    }
    if (last) done_.notify_one();
  }
}

void AsyncVectorEnv::start_all() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    running_ = static_cast<int>(threads_.size());
    ++generation_;
  }
  start_.notify_all();
}

void AsyncVectorEnv::wait_all() {
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [&] { return running_ == 0; });
}

void AsyncVectorEnv::step_async(const Value& actions) { begin_step(actions, "step_async()"); }

const VectorStepResult& AsyncVectorEnv::step_wait() { return end_step("step_wait()"); }

}  // namespace pixelgym::vector
