// VectorEnv: the interface of many envs stepped as one, with batched results
// (gymnasium.vector.VectorEnv, 1.x).
#pragma once

#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pixelgym/envs/env.h"

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
/// The mode named `name` as autoreset_mode_name spells it (case-insensitive, underscores ignored:
/// "next_step", "same_step" also accepted). Throws std::invalid_argument listing the names.
AutoresetMode parse_autoreset_mode(const std::string& name);

/// The envs' metadata (env 0's) and the autoreset mode (Gymnasium's metadata["autoreset_mode"]).
struct VectorMetadata : Metadata {
  /// The mode the vector env was built with.
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
  /// bool (num_envs,): whether env i's task ended its episode at this step.
  Array terminated;
  /// bool (num_envs,): whether env i's episode was cut off at this step (a time limit).
  Array truncated;
  /// As VectorResetResult::infos.
  Info infos;
};

/// The vector env protocol, named as in Gymnasium 1.x: `num_envs()` copies of one env (same
/// spaces) stepped together, with results batched along a leading num_envs axis. Implemented by
/// the batch runner (BatchRunner: SyncVectorEnv's loop, AsyncVectorEnv's thread pool), which runs
/// the envs, and by every vector wrapper (VectorWrapper), which holds another VectorEnv.
///
/// Results. The returned references, and the arrays in them, are the vector env's buffers:
/// **they are overwritten by the next reset or step**. Keep what must outlive the next call with
/// `clone()` (`Value kept = result.obs.clone();`, `Array rewards = result.rewards.clone();`).
/// The caller's actions are copied before any env sees them: they may change as soon as `step`
/// returns.
///
/// Seeding: `reset(seed)` resets env i with seed `seed + i`; `reset()` resets every env unseeded
/// (continuing its generator). Autoresets are unseeded.
///
/// Errors. Calls out of order throw ResetNeeded (step before reset, after close, a kDisabled step
/// for an env whose episode ended). Actions not laid out as action_space() throw
/// std::invalid_argument naming the expected space and the actions given, before any env steps.
/// An env's failure is reported as BatchRunner says.
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
                                 const Options& options = {}) {
    return do_reset(seed, options, nullptr);
  }
  /// Resets the envs whose entry of `reset_mask` (a bool (num_envs,) array, at least one true)
  /// is true, as `reset` would. Gymnasium passes the mask as options["reset_mask"]; here it is
  /// an argument of its own because Options (Params) hold scalars and strings, not arrays; the
  /// other rows of the observation batch keep their last observation and their infos are absent.
  /// Throws std::invalid_argument for a mask of another dtype or shape or with no true entry.
  const VectorResetResult& reset(std::optional<std::uint64_t> seed, const Options& options,
                                 const Array& reset_mask) {
    return do_reset(seed, options, &reset_mask);
  }
  /// Steps every env with its row of `actions` (laid out as action_space()), autoresetting as
  /// `autoreset_mode()` says.
  const VectorStepResult& step(const Value& actions) { return do_step(actions); }
  /// Closes every env. Calling it again does nothing.
  virtual void close() = 0;

  /// How many envs it steps, >= 1.
  virtual int num_envs() const = 0;
  /// One env's spaces (every env's are equal).
  virtual const Space& single_observation_space() const = 0;
  virtual const Space& single_action_space() const = 0;
  /// The batched spaces (see batch_space).
  virtual const Space& observation_space() const = 0;
  virtual const Space& action_space() const = 0;
  /// Env 0's metadata and the autoreset mode.
  virtual const VectorMetadata& metadata() const = 0;
  /// metadata().autoreset_mode.
  AutoresetMode autoreset_mode() const { return metadata().autoreset_mode; }
  /// True once `close()` was called.
  virtual bool closed() const = 0;
  /// "SyncVectorEnv(CartPoleSwingup-v0, num_envs=4)",
  /// "NormalizeReward<SyncVectorEnv(CartPoleSwingup-v0, num_envs=4)>".
  virtual std::string name() const = 0;
  /// Env `i`, for inspection between calls (see BatchRunner::env). Throws std::out_of_range.
  virtual const Env& env(int i) const = 0;
  /// Every env's current render() frame, env 0 first: (H, W, 3) uint8 arrays, new memory
  /// (Gymnasium's VectorEnv.render() with render_mode "rgb_array"). Between calls only. Throws
  /// ResetNeeded after close() or while a step_async() is pending, and what an env's render()
  /// throws (ResetNeeded before its first reset).
  virtual std::vector<Array> render() = 0;

  /// The VectorEnv beneath every wrapper (this one when it is not a wrapper).
  virtual VectorEnv& unwrapped() { return *this; }
  virtual const VectorEnv& unwrapped() const { return *this; }

 protected:
  VectorEnv() = default;

  /// reset: `reset_mask` null for every env, else the mask (checked by the BatchRunner).
  virtual const VectorResetResult& do_reset(std::optional<std::uint64_t> seed,
                                            const Options& options, const Array* reset_mask) = 0;
  /// step.
  virtual const VectorStepResult& do_step(const Value& actions) = 0;
};

}  // namespace pixelgym::vector
