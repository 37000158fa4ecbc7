// VectorWrapper: a vector env that owns another and passes every call through to it
// (gymnasium.vector.VectorWrapper), the base of the vector-aware wrappers.
//
// The vector wrappers (wrappers/vector/, Gymnasium's gymnasium.wrappers.vector.*):
//   RecordEpisodeStatistics  each env's episode return, length and time in infos["episode"]
//   NormalizeObservation     observations normalized with statistics shared across the batch
//   NormalizeReward          rewards scaled by the return variance shared across the batch
// They see the whole batch, so their statistics are the batch's (one set shared by every env),
// where a per-env wrapper in make_vec's wrapping keeps one set per env. Frame stacking stays per
// env (wrappers::FrameStackObservation in the wrapping): each env's stack restarts exactly when
// that env resets, whatever the autoreset mode (tests/wrappers/vector/frame_stack_test.cc).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "pixelgym/envs/vector/vector_env.h"

namespace pixelgym::vector {

/// A VectorEnv that holds another (a BatchRunner, or another VectorWrapper) and forwards every
/// call to it: reset (both forms), step, close, the spaces, metadata, num_envs
/// (gymnasium.vector.VectorWrapper). Subclasses override the do_* hooks that change something,
/// as Env's wrappers do; wrappers stack:
/// `NormalizeReward(std::make_unique<RecordEpisodeStatistics>( make_vec(...)))`.
///
/// Results. As every VectorEnv's, the results are views of buffers that the next reset or step
/// overwrites; a wrapper's are its own (or its inner env's, for what it leaves unchanged), bound
/// once: forwarding a result allocates nothing unless infos are not empty (their Dict is copied
/// then, as BatchRunner builds it then). Steps go through the inner env's `step()`
/// (AsyncVectorEnv's step_async / step_wait are not forwarded).
///
/// Errors: what the inner env throws, unchanged (ResetNeeded for calls out of order, actions not
/// laid out as action_space(), a failed env). One thread at a time calls a vector wrapper.
class VectorWrapper : public VectorEnv {
 public:
  /// Owns `env`. Throws std::invalid_argument when `env` is null.
  explicit VectorWrapper(std::unique_ptr<VectorEnv> env);
  /// Wraps `env` without owning it: the caller keeps it alive for the wrapper's life (as a
  /// Gymnasium wrapper holds a reference). For code that is handed a VectorEnv& and adds a
  /// wrapper of its own around it (ppo::Trainer).
  explicit VectorWrapper(VectorEnv& env);
  ~VectorWrapper() override;

  /// Closes the inner env (calling it again does nothing).
  void close() override { env_->close(); }

  int num_envs() const override { return env_->num_envs(); }
  /// The spaces as this wrapper changes them (the inner env's when it does not).
  const Space& single_observation_space() const override;
  const Space& single_action_space() const override { return env_->single_action_space(); }
  const Space& observation_space() const override;
  const Space& action_space() const override { return env_->action_space(); }
  const VectorMetadata& metadata() const override { return env_->metadata(); }
  bool closed() const override { return env_->closed(); }
  /// "NormalizeReward<SyncVectorEnv(CartPoleSwingup-v0, num_envs=4)>".
  std::string name() const override;
  /// Env `i` of the VectorEnv underneath. Throws std::out_of_range.
  const Env& env(int i) const override { return env_->env(i); }
  /// The inner env's frames (a wrapper changes observations, not what the envs render).
  std::vector<Array> render() override { return env_->render(); }

  /// The VectorEnv beneath every wrapper.
  VectorEnv& unwrapped() override { return env_->unwrapped(); }
  const VectorEnv& unwrapped() const override { return env_->unwrapped(); }
  /// The env one level in.
  VectorEnv& inner() { return *env_; }
  const VectorEnv& inner() const { return *env_; }

 protected:
  /// The class name used in name().
  virtual std::string type_name() const { return "VectorWrapper"; }
  /// The defaults return the inner env's results.
  const VectorResetResult& do_reset(std::optional<std::uint64_t> seed, const Options& options,
                                    const Array* reset_mask) override;
  const VectorStepResult& do_step(const Value& actions) override;

  /// The inner env's reset (with the mask when not null) and step.
  const VectorResetResult& reset_inner(std::optional<std::uint64_t> seed, const Options& options,
                                       const Array* reset_mask);
  const VectorStepResult& step_inner(const Value& actions) { return env_->step(actions); }

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
  std::unique_ptr<VectorEnv> owned_;  // null when the wrapper borrows its env
  VectorEnv* env_;
  SpacePtr single_observation_space_;  // null: the inner env's
  SpacePtr observation_space_;
};

}  // namespace pixelgym::vector
