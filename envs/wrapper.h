// Wrapper bases: Wrapper, ObservationWrapper, ActionWrapper, RewardWrapper (as in Gymnasium).
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "pixelgym/envs/env.h"

namespace pixelgym {

/// Wraps an env and returns the outermost wrapper (the first wrapper innermost): what
/// vector::make_vec applies to each env it makes. wrappers::wrapping builds one from the
/// `--wrap` text form; any callable that takes and returns an env will do.
using EnvWrapping = std::function<std::unique_ptr<Env>(std::unique_ptr<Env> env)>;

/// An env that owns another and, by default, passes every call through to it.
///
/// Only the protocol is forwarded: spaces, metadata, spec, reset/step/render/close. There is no
/// implicit forwarding of anything else (Gymnasium 1.x dropped `__getattr__` forwarding too):
/// reach the inner env with `env()` or the innermost one with `unwrapped()`.
class Wrapper : public Env {
 public:
  /// Throws std::invalid_argument when `env` is null.
  explicit Wrapper(std::unique_ptr<Env> env);

  const Space& observation_space() const override { return env_->observation_space(); }
  const Space& action_space() const override { return env_->action_space(); }
  const Metadata& metadata() const override { return env_->metadata(); }
  Env& unwrapped() override { return env_->unwrapped(); }
  const EnvSpec* spec() const override { return env_->spec(); }
  /// "TimeLimit<GridWorld-v0>".
  std::string name() const override { return type_name() + "<" + env_->name() + ">"; }
  /// The inner env's buffer when this wrapper's observation space is the inner env's (the same
  /// Space object), so that sharing below (FrameStackObservation) survives TimeLimit and the
  /// action and reward wrappers above it; else `observation_space().zeros()`. A subclass that
  /// writes into `out.obs` itself after the inner env did (rather than through
  /// ObservationWrapper) must override this to return `observation_space().zeros()`: the inner
  /// env's buffer may be memory that other observations share.
  Value observation_buffer(BufferFor call) override;

  /// The env one level in.
  Env& env() { return *env_; }
  const Env& env() const { return *env_; }

 protected:
  std::string type_name() const override { return "Wrapper"; }
  /// Forward to the inner env's reset_into / step_into with the same `out`.
  void do_reset(std::optional<std::uint64_t> seed, const Options& options,
                ResetResult& out) override;
  void do_step(const Value& action, StepResult& out) override;
  Array do_render() override;
  void do_close() override;

  /// The wrapped env, owned; never null.
  std::unique_ptr<Env> env_;
};

/// Swaps two Values now and back when it goes out of scope, even by an exception: how a wrapper
/// lets the inner env write into a buffer of the wrapper's own through the caller's result (the
/// caller's `out.obs` is swapped with the wrapper's buffer around the inner call), so that the
/// caller gets its own buffer back whatever happens. Allocates nothing.
class SwapBack {
 public:
  /// Swaps `a` and `b`, which must outlive the SwapBack.
  SwapBack(Value& a, Value& b) : a_(a), b_(b) { a_.swap(b_); }
  /// Swaps them back.
  ~SwapBack() { a_.swap(b_); }
  SwapBack(const SwapBack&) = delete;
  SwapBack& operator=(const SwapBack&) = delete;

 private:
  Value& a_;
  Value& b_;
};

/// A wrapper that transforms observations. Subclasses implement `observation()` and, when it
/// changes the space, call `set_observation_space()` from their constructor.
///
/// The inner env writes into a buffer this wrapper owns (allocated on the first reset), and
/// `observation()` writes the transformed observation into the caller's; so a stack of
/// observation wrappers allocates nothing per step beyond what `observation()` does.
class ObservationWrapper : public Wrapper {
 public:
  using Wrapper::Wrapper;
  /// The space given to set_observation_space(), else the inner env's.
  const Space& observation_space() const override;
  /// `observation_space().zeros()`: observations are transformed, never the inner env's memory.
  Value observation_buffer(BufferFor call) override;

 protected:
  /// Writes the transform of `obs` (laid out as the inner env's observation space) into the
  /// arrays of `out` (laid out as observation_space()).
  virtual void observation(const Value& obs, Value& out) = 0;
  /// Sets the observation space this wrapper reports. Throws std::invalid_argument for null.
  void set_observation_space(SpacePtr space);
  void do_reset(std::optional<std::uint64_t> seed, const Options& options,
                ResetResult& out) override;
  void do_step(const Value& action, StepResult& out) override;

 private:
  SpacePtr observation_space_;      // null: the inner env's
  std::optional<Value> inner_obs_;  // the inner env's observation, allocated on the first reset
};

/// A wrapper that transforms actions before the inner env sees them. Subclasses implement
/// `action()` and, when it changes the space, call `set_action_space()` from their constructor.
class ActionWrapper : public Wrapper {
 public:
  using Wrapper::Wrapper;
  /// The space given to set_action_space(), else the inner env's.
  const Space& action_space() const override;

 protected:
  /// Writes the inner env's action for `action` into the arrays of `out` (laid out as the inner
  /// env's action space, owned by this wrapper).
  virtual void action(const Value& action, Value& out) = 0;
  /// Sets the action space this wrapper reports (and Env::step checks actions against). Throws
  /// std::invalid_argument for null.
  void set_action_space(SpacePtr space);
  void do_step(const Value& action, StepResult& out) override;

 private:
  SpacePtr action_space_;              // null: the inner env's
  std::optional<Value> inner_action_;  // allocated on the first step
};

/// A wrapper that transforms rewards. Subclasses implement `reward()`.
class RewardWrapper : public Wrapper {
 public:
  using Wrapper::Wrapper;

 protected:
  /// The reward the caller sees for the inner env's `reward`.
  virtual double reward(double reward) = 0;
  void do_step(const Value& action, StepResult& out) override;
};

}  // namespace pixelgym
