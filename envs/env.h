// Env: the Gymnasium environment protocol in C++.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "envs/array.h"
#include "envs/params.h"
#include "envs/rng.h"
#include "envs/space.h"
#include "envs/value.h"

namespace pixelgym {

struct EnvSpec;

/// Extra information returned beside observations (Gymnasium's `info` dict).
using Info = ValueDict;

/// Settings passed to `reset` (Gymnasium's `options`).
using Options = Params;

/// What an env can render, and how fast its frames are meant to play.
struct Metadata {
  std::vector<std::string> render_modes{"rgb_array"};
  /// Frames per second of `render()` output played back in real time; > 0.
  double render_fps = 0.0;
};

/// What `reset` returns.
struct ResetResult {
  Value obs;
  Info info;
};

/// What `step` returns. `terminated`: the task's own end (goal reached, pole fell);
/// `truncated`: cut off from outside the task (a time limit).
struct StepResult {
  Value obs;
  double reward = 0.0;
  bool terminated = false;
  bool truncated = false;
  Info info;
};

/// Thrown for calls in the wrong order: `step` or `render` before the first `reset`, `step` after
/// the episode ended without a new `reset`, anything but `close` after `close`. (Gymnasium's
/// `ResetNeeded`.)
class ResetNeeded : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

/// The environment protocol, named as in Gymnasium.
///
/// The public methods are not virtual: they enforce call order, validate actions against
/// `action_space()` and seed the env's generator, then call the protected `do_*` hooks that
/// environments implement. This order enforcement is always on (Gymnasium's `OrderEnforcing`
/// wrapper is opt-out; here it is part of every env).
///
/// Seeding: `reset(seed)` reseeds `rng()` (an xoshiro256** generator, see Rng) from the 64-bit
/// seed; `reset()` without a seed keeps drawing from the current generator, which is seeded from
/// the operating system's entropy if no seed was ever given.
///
/// An Env is used from one thread at a time.
class Env {
 public:
  virtual ~Env() = default;
  Env(const Env&) = delete;
  Env& operator=(const Env&) = delete;

  /// Starts an episode. Throws ResetNeeded after `close()`.
  ResetResult reset(std::optional<std::uint64_t> seed = std::nullopt, const Options& options = {});
  /// Advances one step. Throws ResetNeeded when called out of order and std::invalid_argument
  /// when `action` is not in `action_space()` (naming the space and the value).
  StepResult step(const Value& action);
  /// The current frame as an (H, W, 3) uint8 array (render mode "rgb_array"). Throws
  /// ResetNeeded before the first `reset` or after `close`.
  Array render();
  /// Releases the env's resources. Calling it again does nothing.
  void close();

  virtual const Space& observation_space() const = 0;
  virtual const Space& action_space() const = 0;
  virtual const Metadata& metadata() const = 0;

  /// The innermost env beneath any wrappers.
  virtual Env& unwrapped() { return *this; }
  /// The registry entry this env was made from; null for an env constructed directly.
  virtual const EnvSpec* spec() const { return spec_.get(); }
  /// Set by the registry on the env it makes.
  void set_spec(std::shared_ptr<const EnvSpec> spec) { spec_ = std::move(spec); }
  /// How error messages name this env: the registered id, "TimeLimit<GridWorld-v0>" for a
  /// wrapper, or the class name given by `type_name()`.
  virtual std::string name() const;

  /// This env's generator (Gymnasium's `np_random`).
  Rng& rng();
  /// True once `close()` was called.
  bool closed() const { return closed_; }

 protected:
  Env() = default;

  /// The class name used in messages when the env is not registered.
  virtual std::string type_name() const { return "Env"; }

  /// Starts an episode; `rng()` is already seeded. `seed` is passed on so that wrappers can
  /// forward it to the env they wrap.
  virtual ResetResult do_reset(std::optional<std::uint64_t> seed, const Options& options) = 0;
  /// Advances one step with an action already known to be in `action_space()`.
  virtual StepResult do_step(const Value& action) = 0;
  virtual Array do_render() = 0;
  /// Called at most once.
  virtual void do_close() {}

 private:
  std::shared_ptr<const EnvSpec> spec_;
  std::optional<Rng> rng_;
  bool has_reset_ = false;
  bool episode_over_ = false;
  bool closed_ = false;
};

}  // namespace pixelgym
