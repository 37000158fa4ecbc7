// VectorEnv: many envs stepped as one, with batched results (gymnasium.vector.VectorEnv, 1.x).
#pragma once

#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "envs/env.h"
#include "render/mesa_copy.h"
#include "render/renderer.h"

namespace pixelgym::vector {

/// What a vector env does with an env whose episode ended (Gymnasium 1.1's AutoresetMode; see
/// https://farama.org/Vector-Autoreset-Mode).
enum class AutoresetMode : std::uint8_t {
  /// Gymnasium's default. The step after the one that ended env i's episode ignores env i's
  /// action and resets it instead (unseeded, continuing its generator): that step returns the
  /// reset observation and the reset's info for env i, reward 0 and both flags false.
  kNextStep,
  /// The step that ends env i's episode resets it at once: it returns the reset observation and
  /// the reset's info for env i, with the episode's last observation in infos["final_obs"] (a
  /// batch laid out as observation_space(), rows of envs that did not end zero) and the last
  /// step's info in infos["final_info"] (batched as infos are), each with its mask
  /// ("_final_obs", "_final_info": bool (num_envs,)). Reward and flags are the last step's.
  kSameStep,
  /// Never resets by itself: the caller resets the envs that ended with
  /// `reset(seed, options, reset_mask)` before the next step (which throws ResetNeeded otherwise).
  kDisabled,
};

/// "NextStep", "SameStep" or "Disabled" (Gymnasium's names).
const char* autoreset_mode_name(AutoresetMode mode);
/// The mode named `name` as autoreset_mode_name spells it (case-insensitive; "next_step",
/// "same_step" also accepted). Throws std::invalid_argument listing the names.
AutoresetMode parse_autoreset_mode(const std::string& name);

/// The envs' metadata (env 0's) and the autoreset mode (Gymnasium's metadata["autoreset_mode"]).
struct VectorMetadata : Metadata {
  AutoresetMode autoreset_mode = AutoresetMode::kNextStep;
};

/// What `reset` returns: views of buffers the vector env owns (see VectorEnv).
struct VectorResetResult {
  /// Laid out as observation_space(): row i is env i's observation.
  Value obs;
  /// Per-env infos batched as Gymnasium does: each key an array with a leading num_envs axis
  /// (zero in the rows of envs that did not report it) beside "_key", a bool (num_envs,) mask of
  /// the envs that did; a Dict info value becomes a Dict batched the same way.
  Info infos;
};

/// What `step` returns: views of buffers the vector env owns (see VectorEnv).
struct VectorStepResult {
  /// The same arrays as VectorResetResult::obs.
  Value obs;
  /// float64 (num_envs,).
  Array rewards;
  /// bool (num_envs,) each.
  Array terminated;
  Array truncated;
  /// As VectorResetResult::infos.
  Info infos;
};

/// Builds env `index` of a vector env. Called once per index; AsyncVectorEnv calls it on the
/// worker thread that will run that env, several at once: it must be safe to call from several
/// threads (`make` is).
using EnvFactory = std::function<std::unique_ptr<Env>(int index)>;

/// The vector env protocol, named as in Gymnasium 1.x: `num_envs()` copies of one env (same
/// spaces) stepped together, with results batched along a leading num_envs axis.
///
/// Buffers. Every result lives in arrays the vector env allocates once, at construction: the
/// observation batch (laid out as observation_space(), shared by reset and step results), the
/// rewards and the flags. Each env writes its observation straight into its row (a view, through
/// Env::reset_into / step_into, wrappers included), so a step copies no observation and, once
/// warmed up, allocates nothing on the heap when no env reports info (a step whose infos are not
/// empty builds the batched info arrays, as Gymnasium does). Actions are copied into a batch of
/// the vector env's own before any env sees them, so the caller's actions may change as soon as
/// `step` (or AsyncVectorEnv::step_async) returns.
///
/// **The returned results are overwritten by the next reset or step**: the references, and the
/// arrays in them, are the vector env's buffers. Keep what must outlive the next call with
/// `clone()` (`Value kept = result.obs.clone();`, `Array rewards = result.rewards.clone();`).
///
/// Seeding: `reset(seed)` resets env i with seed `seed + i`; `reset()` resets every env unseeded
/// (continuing its generator). Autoresets are unseeded.
///
/// Errors. Calls out of order throw ResetNeeded (step before reset, after close, a kDisabled step
/// for an env whose episode ended). Actions not laid out as action_space() throw
/// std::invalid_argument naming the expected space and the actions given, before any env steps.
/// When an env throws, the others still finish the call; then the vector env throws an
/// exception of the original's type (std::invalid_argument, std::out_of_range, ResetNeeded, else
/// std::runtime_error) whose message is "<name>: env <i> (<env name>): <original message>", for
/// the lowest failing index. After that every call but `reset()` (without a mask) and `close()`
/// throws ResetNeeded: the batch is not a consistent state. A full `reset()` makes the vector
/// env usable again (worker threads are kept).
///
/// GL contexts. By default the pixel envs that one thread runs draw with one shared GL context
/// (render::SharedContext: one for SyncVectorEnv, one per worker of AsyncVectorEnv), sharing its
/// compiled shaders, uploaded meshes and scratch framebuffers; each env keeps its own Bullet
/// world and scene, and its frames are byte-identical to an env drawing with a context of its
/// own. Separate contexts keep a copy of all that each, which at 8 envs on one core costs about a
/// fifth of the steps per second (see render::SharedContext); `share_gl_contexts = false` gives
/// every env its own context instead.
///
/// Copies of Mesa. The contexts of the envs that worker thread w runs (w = i % threads for env i)
/// are created in copy w of Mesa (render::MesaCopy): copy 0, the linked libOSMesa, for
/// SyncVectorEnv and for AsyncVectorEnv's worker 0 (whose envs also run on the caller), private
/// copies for the other workers. llvmpipe rasterizes the frames of one copy's contexts one at a
/// time, so without this a second thread added 10-30 % to pixel steps; with it, threads render in
/// parallel. The copies give byte-identical frames.
///
/// One thread at a time calls a vector env's methods.
class VectorEnv {
 public:
  virtual ~VectorEnv();
  VectorEnv(const VectorEnv&) = delete;
  VectorEnv& operator=(const VectorEnv&) = delete;

  /// Resets every env (env i with `seed + i` when a seed is given, with `options`). Clears the
  /// error state left by a failed call.
  const VectorResetResult& reset(std::optional<std::uint64_t> seed = std::nullopt,
                                 const Options& options = {});
  /// Resets the envs whose entry of `reset_mask` (a bool (num_envs,) array, at least one true)
  /// is true, as `reset` would. Gymnasium passes the mask as options["reset_mask"]; here it is
  /// an argument of its own because Options (Params) hold scalars and strings, not arrays; the
  /// other rows of the observation batch keep their last observation and their infos are absent.
  /// Throws std::invalid_argument for a mask of another dtype or shape or with no true entry.
  const VectorResetResult& reset(std::optional<std::uint64_t> seed, const Options& options,
                                 const Array& reset_mask);
  /// Steps every env with its row of `actions` (laid out as action_space()), autoresetting as
  /// `autoreset_mode()` says.
  const VectorStepResult& step(const Value& actions);
  /// Closes every env (on the thread that runs it). Calling it again does nothing. Throws the
  /// first env's close error, as a step error is reported, after closing the others.
  void close();

  int num_envs() const { return num_envs_; }
  /// One env's spaces (env 0's; every env's are equal).
  const Space& single_observation_space() const;
  const Space& single_action_space() const;
  /// The batched spaces (see batch_space).
  const Space& observation_space() const { return *observation_space_; }
  const Space& action_space() const { return *action_space_; }
  const VectorMetadata& metadata() const { return metadata_; }
  AutoresetMode autoreset_mode() const { return metadata_.autoreset_mode; }
  bool closed() const { return closed_; }
  /// "SyncVectorEnv(CartPoleSwingup-v0, num_envs=4)".
  std::string name() const;
  /// Env `i`, for inspection between calls (never while AsyncVectorEnv has a step pending).
  /// AsyncVectorEnv runs env i on one worker thread: calling its methods from another thread
  /// makes its GL context current there (see AsyncVectorEnv). Throws std::out_of_range.
  const Env& env(int i) const;

 protected:
  /// Throws std::invalid_argument naming `type_name` unless num_envs >= 1.
  VectorEnv(std::string type_name, int num_envs, AutoresetMode autoreset, bool share_gl_contexts);

  /// Builds the envs with `make_env` (through run_all: on the threads that will run them), checks
  /// that their spaces agree and allocates every buffer. Env i draws with shared GL context
  /// i % `context_groups` (when sharing): one per thread that runs envs; its contexts are of
  /// Mesa copy i % `context_groups` (render::MesaCopy). Subclass constructors
  /// call it last.
  /// Throws what make_env throws (with the env index), destroying the envs already built, or
  /// std::invalid_argument when an env's spaces differ from env 0's or cannot be batched.
  void build(const EnvFactory& make_env, int context_groups);
  /// Destroys the envs through run_all. AsyncVectorEnv's destructor calls it while its workers
  /// still run; the base destructor destroys what is left on the calling thread.
  void destroy_envs() noexcept;

  /// Starts `run_env(i)` for every env i (on the calling thread or others) and returns; the
  /// calls may still be running.
  virtual void start_all() = 0;
  /// Returns once every call begun by start_all has returned.
  virtual void wait_all() = 0;
  /// Runs `run_env(i)` for every env i and returns when all have returned: start_all() then
  /// wait_all(), unless a subclass does better (AsyncVectorEnv runs a share on the caller).
  virtual void run_all();
  /// Does env i's part of the current call; catches what it throws (see VectorEnv: Errors).
  void run_env(int i) noexcept;

  /// The two halves of step(): validates and copies `actions` and starts the envs (all at once
  /// through run_all when `wait`, else through start_all); then waits for them (unless they
  /// finished) and batches the results. AsyncVectorEnv exposes them as step_async / step_wait.
  void begin_step(const Value& actions, const char* method, bool wait);
  const VectorStepResult& end_step(const char* method);
  bool step_pending() const { return step_pending_; }

 private:
  enum class Phase : std::uint8_t { kBuild, kReset, kStep, kClose, kDestroy };

  void run_phase(Phase phase);
  void step_env(int i);
  void require_usable(const char* method) const;
  const VectorResetResult& do_reset(std::optional<std::uint64_t> seed, const Options& options,
                                    const Array* reset_mask);
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
  bool share_gl_contexts_;
  int context_groups_ = 1;                                               // threads that run envs
  std::vector<std::unique_ptr<render::SharedContext>> shared_contexts_;  // env i: i % size

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
