// ProcessVectorEnv: the envs stepped in worker processes that write into shared memory
// (gymnasium.vector.AsyncVectorEnv with shared_memory=True, SB3's SubprocVecEnv).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pixelgym/envs/env.h"
#include "pixelgym/envs/vector/batch_runner.h"
#include "pixelgym/envs/vector/vector_env.h"

namespace pixelgym::vector {

/// A VectorEnv whose envs are stepped by `num_workers()` worker processes, each running a
/// contiguous block of them (8 envs on 3 workers: envs 0-2, 3-5 and 6-7) in a loop. With
/// `caller_steps_envs` (the default) worker 0 is the calling process, which steps its block while
/// the child processes step theirs (as AsyncVectorEnv's calling thread runs thread 0's share);
/// without it every worker is a child (an env that crashes cannot take the caller with it). Why
/// processes: each has its own copy of everything the envs use, the rasterizer included, so the
/// workers scale as independent processes do (a thread pool shares one Mesa: see
/// docs/vector.md).
///
/// Memory. The observation batch, the actions, the rewards and the flags are arrays in memory
/// shared with the workers (mmap): each worker writes its envs' observations straight into their
/// rows of the batch (nothing is copied or sent for them), and reads its actions from it. What
/// varies in size (the batched infos, final_obs under kSameStep, errors, render() frames) comes
/// back over a socket, only when there is some.
///
/// Workers. The children are made by fork() in the constructor, before the caller builds any env
/// of its own, so whatever the process registered (a
/// user's own tasks in a Registry) reaches them; each calls `make_worker_envs(w)` once and builds
/// its envs with the factory it returns (so that what they share, such as rendering resources, is
/// made in the worker). Make a ProcessVectorEnv before the process draws on a GPU (a GPU context
/// does not survive fork()), and while no other thread is making envs (fork() copies only the
/// calling thread: a lock another thread held stays taken in the child). A worker serves one
/// vector env and ends with it.
///
/// Results are byte-identical to SyncVectorEnv's for the same seeds and actions, whatever the
/// number of workers, under every autoreset mode.
///
/// Errors. An env's error is reported as BatchRunner's, with the worker:
/// "ProcessVectorEnv(CartPoleSwingup-v1, num_envs=8): env 5 (TimeLimit<...>) on worker 1 (pid
/// 4242): <message>", the same type. A worker that dies (killed, crashed) makes the call that
/// waits for it throw std::runtime_error naming the worker, its pid, its envs and how it ended,
/// within about 0.1 s of its death; every later call but close() throws ResetNeeded, and close()
/// returns, ending the other workers. The destructor ends the workers without calling the envs'
/// close(), waiting for each at most a few seconds before killing it.
class ProcessVectorEnv final : public VectorEnv {
 public:
  /// Builds a worker's env factory, in that worker (called once per worker, with its index).
  using WorkerFactory = std::function<EnvFactory(int worker)>;

  /// Starts the workers and builds env i with the factory of the worker that runs it.
  /// `like` says what every env is (spaces, metadata, spec: make_vec passes a DescribedEnv with
  /// the wrapping applied): the shared buffers are laid out from its spaces before any env is
  /// built, and each worker checks its envs against them. env(i) returns it.
  /// Throws std::invalid_argument for num_envs < 1, num_workers < 0, or envs whose spaces differ
  /// from `like`'s; std::runtime_error when a worker cannot be started or dies; and what an env's
  /// factory throws, naming the env (the workers are ended first).
  ProcessVectorEnv(int num_envs, const WorkerFactory& make_worker_envs,
                   std::shared_ptr<const Env> like, int num_workers = 0,
                   AutoresetMode autoreset = AutoresetMode::kNextStep,
                   bool caller_steps_envs = true);
  ~ProcessVectorEnv() override;

  /// Closes every env (in its worker), then ends the workers. Calling it again does nothing.
  /// Throws the first env's close error, after ending every worker.
  void close() override;

  int num_envs() const override { return num_envs_; }
  const Space& single_observation_space() const override { return like_->observation_space(); }
  const Space& single_action_space() const override { return like_->action_space(); }
  const Space& observation_space() const override { return *observation_space_; }
  const Space& action_space() const override { return *action_space_; }
  const VectorMetadata& metadata() const override { return metadata_; }
  bool closed() const override { return closed_; }
  /// "ProcessVectorEnv(CartPoleSwingup-v1, num_envs=8)".
  std::string name() const override;
  /// The `like` env: the envs themselves live in the workers. Throws std::out_of_range for i
  /// outside [0, num_envs).
  const Env& env(int i) const override;
  /// Every env's frame, rendered in its worker and sent back.
  std::vector<Array> render() override;

  /// Worker processes (after clamping to num_envs).
  int num_workers() const;
  /// The process id of worker `w` (for tests and diagnostics). Throws std::out_of_range.
  int worker_pid(int w) const;
  /// The num_workers() a ProcessVectorEnv of `num_envs` envs asked for `num_workers` has: 0 means
  /// one per core; more workers than envs are clamped to num_envs. Throws std::invalid_argument
  /// for num_workers < 0.
  static int workers_for(int num_envs, int num_workers);

 protected:
  const VectorResetResult& do_reset(std::optional<std::uint64_t> seed, const Options& options,
                                    const Array* reset_mask) override;
  const VectorStepResult& do_step(const Value& actions) override;

 private:
  struct Worker;
  struct Shared;
  struct Block;

  // Builds worker w's envs (in the process that will run them).
  std::unique_ptr<Block> build_block(int w, const WorkerFactory& make_worker_envs);
  void start_worker(int w, const WorkerFactory& make_worker_envs);
  // The child's side of start_worker: builds worker w's envs and serves calls until the parent
  // closes its socket or sends kClose. `inherited`: the parent's sockets it must close.
  void serve_as_worker(int w, const int ends[2], const std::vector<int>& inherited,
                       const WorkerFactory& make_worker_envs);
  // Sends `command` to each worker for which it is not empty and returns each one's reply (empty
  // for those not called), in worker order; a dead worker throws (see Errors).
  std::vector<std::string> call(const std::vector<std::string>& commands, const char* method);
  // Waits for a reply from each worker marked in `pending` (those marked in `died` could not be
  // sent their command); throws std::runtime_error for a worker that died.
  std::vector<std::string> await(std::vector<std::uint8_t> pending, std::vector<std::uint8_t> died,
                                 const char* method);
  // Throws the lowest worker's error among `replies`; returns the successful replies' bodies.
  void throw_first_error(std::vector<std::string>& replies, bool poison);
  void require_usable(const char* method) const;
  // Batches the replies' infos into `infos` (each worker's at its rows).
  void batch_infos(const std::vector<std::string>& replies, Info& infos);
  void end_workers() noexcept;

  int num_envs_;
  std::shared_ptr<const Env> like_;
  std::string id_;
  SpacePtr observation_space_;
  SpacePtr action_space_;
  VectorMetadata metadata_;
  std::shared_ptr<Shared> shared_;
  std::vector<Worker> workers_;
  std::unique_ptr<Block> own_;  // caller_steps_envs: worker 0's envs, in this process

  VectorResetResult reset_result_;
  VectorStepResult step_result_;
  Value actions_;                    // in shared memory, laid out as action_space()
  std::vector<std::uint8_t> ended_;  // kDisabled: env i's episode ended at the last step

  bool spin_ = false;      // workers <= cores: wait without sleeping first
  bool own_core_ = false;  // and a core for each process, the caller's included: pause, not yield
  bool has_reset_ = false;
  bool failed_ = false;
  bool dead_ = false;  // a worker died: only close() is left
  bool closed_ = false;
};

}  // namespace pixelgym::vector
