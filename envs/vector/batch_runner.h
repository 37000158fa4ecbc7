// BatchRunner: the VectorEnv that runs its own envs, in a loop (SyncVectorEnv) or on a thread
// pool (AsyncVectorEnv).
#pragma once

#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pixelgym/envs/env.h"
#include "pixelgym/envs/vector/vector_env.h"

namespace pixelgym::vector {

/// Builds env `index` of a vector env. Called once per index; AsyncVectorEnv calls it on the
/// worker thread that will run that env, several at once: it must be safe to call from several
/// threads (`make` is). What the envs share (their rendering resources) is the factory's to give
/// them: make_vec's factory hands env i the resources of the thread that runs it.
using EnvFactory = std::function<std::unique_ptr<Env>(int index)>;

/// Arrays a BatchRunner writes its results into instead of allocating its own: ProcessVectorEnv's
/// workers write their rows of the batch, in memory shared with the parent process.
struct BatchBuffers {
  /// Laid out as the runner's observation_space().
  Value obs;
  /// float64 (num_envs,).
  Array rewards;
  /// bool (num_envs,) each.
  Array terminated;
  Array truncated;
};

/// Throws std::invalid_argument naming `envs` unless `reset_mask` is a bool (num_envs,) array
/// with a true entry (VectorEnv::reset's mask), then ResetNeeded when `failed` (a failed call
/// leaves only a full reset).
void check_reset_mask(const VectorEnv& envs, const Array& reset_mask, bool failed);
/// Throws std::invalid_argument naming `envs` and `method` unless `actions` are laid out as
/// envs.action_space().
void check_actions(const VectorEnv& envs, const Value& actions, const char* method);
/// Under kDisabled, throws ResetNeeded naming the first env whose entry of `ended` is set (its
/// episode ended at the last step and it was not reset since).
void check_none_ended(const VectorEnv& envs, const std::vector<std::uint8_t>& ended,
                      const char* method);

/// The VectorEnv that owns and runs `num_envs()` envs; its subclasses say on which threads
/// (SyncVectorEnv: a loop on the caller; AsyncVectorEnv: a pool of workers). It knows nothing
/// of what the envs do inside (rendering included).
///
/// Buffers. Every result lives in arrays allocated once, at construction: the observation batch
/// (laid out as observation_space(), shared by reset and step results), the rewards and the
/// flags. Each env writes its observation straight into its row (a view, through
/// Env::reset_into / step_into, wrappers included), so a step copies no observation and, once
/// warmed up, allocates nothing on the heap when no env reports info (a step whose infos are not
/// empty builds the batched info arrays, as Gymnasium does). Actions are copied into a batch of
/// the runner's own before any env sees them.
///
/// Errors. When an env throws, the others still finish the call; then the runner throws an
/// exception of the original's type (std::invalid_argument, std::out_of_range, ResetNeeded, else
/// std::runtime_error) whose message is "<name>: env <i> (<env name>): <original message>", for
/// the lowest failing index. After that every call but `reset()` (without a mask) and `close()`
/// throws ResetNeeded: the batch is not a consistent state. A full `reset()` makes the runner
/// usable again (worker threads are kept).
class BatchRunner : public VectorEnv {
 public:
  /// Destroys whatever envs a subclass destructor left, on the calling thread, without calling
  /// their close().
  ~BatchRunner() override;

  /// Closes every env (on the thread that runs it). Calling it again does nothing. Throws the
  /// first env's close error, as a step error is reported, after closing the others.
  void close() override;

  int num_envs() const override { return num_envs_; }
  /// Env 0's spaces.
  const Space& single_observation_space() const override;
  const Space& single_action_space() const override;
  /// batch_space of env 0's spaces, built once by build().
  const Space& observation_space() const override { return *observation_space_; }
  const Space& action_space() const override { return *action_space_; }
  /// Env 0's metadata, with the autoreset mode.
  const VectorMetadata& metadata() const override { return metadata_; }
  bool closed() const override { return closed_; }
  /// "SyncVectorEnv(CartPoleSwingup-v0, num_envs=4)": the type name, env 0's registered id (when
  /// it has one) and num_envs.
  std::string name() const override;
  /// Env `i`, for inspection between calls (never while AsyncVectorEnv has a step pending).
  /// AsyncVectorEnv runs env i on one worker thread; a pixel env inspected from another thread
  /// binds its GL context there only for the length of each call (render::Context). Throws
  /// std::out_of_range.
  const Env& env(int i) const override;
  /// Each env's render() on the calling thread (as env(i) is inspected: see above).
  std::vector<Array> render() override;

 protected:
  /// Throws std::invalid_argument naming `type_name` unless num_envs >= 1.
  BatchRunner(std::string type_name, int num_envs, AutoresetMode autoreset);

  /// Builds the envs with `make_env` (through run_all: on the threads that will run them), checks
  /// that their spaces agree and allocates every buffer. Subclass constructors call it last.
  /// Throws what make_env throws (with the env index), destroying the envs already built, or
  /// std::invalid_argument when an env's spaces differ from env 0's or cannot be batched. With
  /// `buffers`, observations, rewards and flags go into those arrays (std::invalid_argument
  /// unless they are laid out as the batch); the others are allocated here.
  void build(const EnvFactory& make_env, const BatchBuffers* buffers = nullptr);
  /// Destroys the envs through run_all. AsyncVectorEnv's destructor calls it while its workers
  /// still run; the base destructor destroys what is left on the calling thread.
  void destroy_envs() noexcept;

  const VectorResetResult& do_reset(std::optional<std::uint64_t> seed, const Options& options,
                                    const Array* reset_mask) override;
  const VectorStepResult& do_step(const Value& actions) override;

  /// Starts `run_env(i)` for every env i (on the calling thread or others) and returns; the
  /// calls may still be running.
  virtual void start_all() = 0;
  /// Returns once every call begun by start_all has returned.
  virtual void wait_all() = 0;
  /// Runs `run_env(i)` for every env i and returns when all have returned: start_all() then
  /// wait_all(), unless a subclass does better (AsyncVectorEnv runs a share on the caller).
  virtual void run_all();
  /// Does env i's part of the current call; catches what it throws (see BatchRunner: Errors).
  void run_env(int i) noexcept;

  /// The two halves of step(): validates and copies `actions` and starts the envs (all at once
  /// through run_all when `wait`, else through start_all); then waits for them (unless they
  /// finished) and batches the results. AsyncVectorEnv exposes them as step_async / step_wait.
  void begin_step(const Value& actions, const char* method, bool wait);
  const VectorStepResult& end_step(const char* method);
  /// Whether begin_step has started a step that end_step has not yet finished.
  bool step_pending() const { return step_pending_; }
  /// How an env's error names it after name(): "env 3 (TimeLimit<CartPoleSwingup>)".
  virtual std::string env_context(int i, const std::string& env_name) const;

 private:
  enum class Phase : std::uint8_t { kBuild, kReset, kStep, kClose, kDestroy };

  void run_phase(Phase phase);
  void step_env(int i);
  void require_usable(const char* method) const;
  void check_buffers(const BatchBuffers& buffers) const;
  // Throws the lowest-index error recorded by run_env, if any, and forgets them all.
  void throw_first_error(bool poison);
  void batch_infos(Info& infos, bool any_final);

  std::string type_name_;
  int num_envs_;
  std::vector<std::unique_ptr<Env>> envs_;
  SpacePtr observation_space_;
  SpacePtr action_space_;
  VectorMetadata metadata_;

  // Buffers, allocated by build().
  VectorResetResult reset_result_;
  VectorStepResult step_result_;
  Value actions_;                        // laid out as action_space()
  std::vector<Value> action_slots_;      // row i of actions_
  std::vector<ResetResult> env_resets_;  // obs: row i of the observation batch
  std::vector<StepResult> env_steps_;    // obs: the same row
  Value final_obs_;                      // kSameStep: laid out as observation_space()
  std::vector<Value> final_obs_slots_;
  std::vector<Info> final_infos_;
  std::vector<const Info*> env_infos_;   // each env's info for this call; null: none
  std::vector<std::uint8_t> autoreset_;  // env i's episode ended at the last step
  std::vector<std::uint8_t> final_;      // kSameStep: env i ended and was reset in this step
  std::vector<std::exception_ptr> errors_;

  // The current call's arguments, read by run_env.
  Phase phase_ = Phase::kBuild;
  const EnvFactory* make_env_ = nullptr;
  std::optional<std::uint64_t> seed_;
  const Options* options_ = nullptr;
  const Array* reset_mask_ = nullptr;

  bool has_reset_ = false;
  bool failed_ = false;  // a call failed: only reset() and close() are allowed
  bool step_pending_ = false;
  bool finished_ = false;  // the pending step ran through run_all: nothing to wait for
  bool closed_ = false;
};

}  // namespace pixelgym::vector
