// VectorWrapper: a vector env that owns another and passes every call through to it
// (gymnasium.vector.VectorWrapper), the base of the vector-aware wrappers.
//
// The vector wrappers (this folder, Gymnasium's gymnasium.wrappers.vector.*):
//   RecordEpisodeStatistics  each env's episode return, length and time in infos["episode"]
//   NormalizeObservation     observations normalized with statistics shared across the batch
//   NormalizeReward          rewards scaled by the return variance shared across the batch
// They see the whole batch, so their statistics are the batch's (one set shared by every env),
// where a per-env wrapper given to make_vec's `wrappers` keeps one set per env.
//
// Frame stacking has no vector wrapper, on purpose: give make_vec the per-env one
// (`{"frame_stack=4"}`, wrappers::FrameStackObservation). Inside a vector env every env is reset
// on its own, exactly when its episode restarts (the autoreset step under NextStep, inside the
// step of the done under SameStep, the masked reset under Disabled), so each env's stack
// restarts for exactly the envs that reset, whatever the mode (pinned by
// tests/envs/vector/wrappers/frame_stack_test.cc). It writes its stacked frames straight into the
// env's batch row on the worker thread that runs the env, and under SameStep the terminal
// stack reaches final_obs like any observation. A vector-level frame stack would have to rebuild
// which rows restarted from the flags and the autoreset mode, copy the same k frames per row
// per step on the calling thread, and would bring no saving in memory or time.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>

#include "envs/vector/vector_env.h"

namespace pixelgym::vector {

class VectorWrapper;

/// What a VectorWrapper wraps, taken from either owner: a `std::unique_ptr` to a VectorEnv
/// (SyncVectorEnv, AsyncVectorEnv, what make_vec returns) or to a VectorWrapper (any subclass),
/// so that wrappers stack: `NormalizeReward(std::make_unique<RecordEpisodeStatistics>(make_vec(
/// ...)))`.
struct InnerVectorEnv {
  template <typename V, std::enable_if_t<std::is_base_of_v<VectorEnv, V>, int> = 0>
  InnerVectorEnv(std::unique_ptr<V> vector_env)  // NOLINT(google-explicit-constructor)
      : env(std::move(vector_env)) {}
  template <typename V, std::enable_if_t<std::is_base_of_v<VectorWrapper, V>, int> = 0>
  InnerVectorEnv(std::unique_ptr<V> vector_wrapper)  // NOLINT(google-explicit-constructor)
      : wrapper(std::move(vector_wrapper)) {}

  std::unique_ptr<VectorEnv> env;  // at most one of the two is set
  std::unique_ptr<VectorWrapper> wrapper;
};

/// A vector env that owns another (a VectorEnv, or another VectorWrapper) and forwards every
/// call to it: reset (both forms), step, close, the spaces, metadata, num_envs. Subclasses
/// override the do_* hooks that change something, as Env's wrappers do.
///
/// Not a VectorEnv subclass: VectorEnv owns its envs and buffers and its public methods are not
/// virtual, so a wrapper could not stand in for one. VectorWrapper has the same public methods
/// with the same names and meanings instead, so code written as a template over the vector env
/// type takes either; `unwrapped()` reaches the VectorEnv underneath.
///
/// Results. As VectorEnv's, the results are views of buffers that the next reset or step
/// overwrites; a wrapper's are its own (or its inner env's, for what it leaves unchanged), bound
/// once: forwarding a result allocates nothing unless infos are not empty (their Dict is copied
/// then, as VectorEnv builds it then). Steps go through the inner env's `step()`
/// (AsyncVectorEnv's step_async / step_wait are not forwarded).
///
/// Errors: what the inner env throws, unchanged (ResetNeeded for calls out of order, actions not
/// laid out as action_space(), a failed env). One thread at a time calls a vector wrapper.
class VectorWrapper {
 public:
  /// Throws std::invalid_argument when `env` holds no env (a null pointer).
  explicit VectorWrapper(InnerVectorEnv env);
  virtual ~VectorWrapper();
  VectorWrapper(const VectorWrapper&) = delete;
  VectorWrapper& operator=(const VectorWrapper&) = delete;

  /// As VectorEnv::reset: every env (env i seeded with `seed + i` when a seed is given).
  const VectorResetResult& reset(std::optional<std::uint64_t> seed = std::nullopt,
                                 const Options& options = {});
  /// As VectorEnv::reset with a mask: the envs whose entry of `reset_mask` is true.
  const VectorResetResult& reset(std::optional<std::uint64_t> seed, const Options& options,
                                 const Array& reset_mask);
  /// As VectorEnv::step.
  const VectorStepResult& step(const Value& actions);
  /// Closes the inner env (calling it again does nothing).
  void close();

  int num_envs() const;
  /// The spaces as this wrapper changes them (the inner env's when it does not).
  const Space& single_observation_space() const;
  const Space& single_action_space() const;
  const Space& observation_space() const;
  const Space& action_space() const;
  const VectorMetadata& metadata() const;
  AutoresetMode autoreset_mode() const { return metadata().autoreset_mode; }
  bool closed() const;
  /// "NormalizeReward<SyncVectorEnv(CartPoleSwingup-v0, num_envs=4)>".
  std::string name() const;
  /// Env `i` of the VectorEnv underneath (see VectorEnv::env). Throws std::out_of_range.
  const Env& env(int i) const;

  /// The VectorEnv beneath every wrapper.
  VectorEnv& unwrapped();
  const VectorEnv& unwrapped() const;
  /// The wrapper one level in; null when this one wraps the VectorEnv itself.
  VectorWrapper* inner_wrapper() { return wrapper_.get(); }
  const VectorWrapper* inner_wrapper() const { return wrapper_.get(); }

 protected:
  /// The class name used in name().
  virtual std::string type_name() const { return "VectorWrapper"; }
  /// reset: `reset_mask` null for every env, else the mask (already checked by the inner env
  /// when reset_inner returns). The default returns the inner env's result.
  virtual const VectorResetResult& do_reset(std::optional<std::uint64_t> seed,
                                            const Options& options, const Array* reset_mask);
  /// step. The default returns the inner env's result.
  virtual const VectorStepResult& do_step(const Value& actions);

  /// The inner env's reset (with the mask when not null) and step.
  const VectorResetResult& reset_inner(std::optional<std::uint64_t> seed, const Options& options,
                                       const Array* reset_mask);
  const VectorStepResult& step_inner(const Value& actions);

  /// Replaces the single observation space (from a subclass constructor); the batched one
  /// becomes batch_space(space, num_envs()). Throws as batch_space.
  void set_single_observation_space(SpacePtr space);

  /// Makes `to` view the arrays of `from` (same structure), unless it views them already:
  /// allocates on the first call only (and when the inner env hands out other buffers).
  static void view(const Value& from, Value& to);
  static void view(const Array& from, Array& to);
  /// `to` = `from`: cleared (no allocation) when `from` is empty, else a copy of the Dict (its
  /// arrays shared).
  static void copy_infos(const Info& from, Info& to);
  /// `out` showing `inner`'s observations, rewards, flags (views) and infos (copied as
  /// copy_infos): the start of a step result a subclass then changes.
  static void forward(const VectorStepResult& inner, VectorStepResult& out);

 private:
  std::unique_ptr<VectorEnv> env_;  // exactly one of env_ and wrapper_ is set
  std::unique_ptr<VectorWrapper> wrapper_;
  SpacePtr single_observation_space_;  // null: the inner env's
  SpacePtr observation_space_;
};

}  // namespace pixelgym::vector
