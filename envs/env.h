// Env: the Gymnasium environment protocol in C++.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/envs/array.h"
#include "pixelgym/envs/errors.h"
#include "pixelgym/envs/params.h"
#include "pixelgym/envs/rng.h"
#include "pixelgym/envs/space.h"
#include "pixelgym/envs/value.h"

namespace pixelgym {

struct EnvSpec;

/// Extra information returned beside observations (Gymnasium's `info` dict).
using Info = ValueDict;

/// Settings passed to `reset` (Gymnasium's `options`).
using Options = Params;

/// What an env can render, and how fast its frames are meant to play.
struct Metadata {
  /// The render modes `render()` supports; pixelgym's envs support "rgb_array" only.
  std::vector<std::string> render_modes{"rgb_array"};
  /// Frames per second of `render()` output played back in real time; > 0.
  double render_fps = 0.0;
  /// The shape of `render()` frames, (H, W, 3), when the env knows it without rendering (pixel
  /// tasks and GridWorld do: it comes from their config); std::nullopt when unknown. Wrappers that
  /// put frames in observations (AddRenderObservation) need it to build their space up front.
  std::optional<Shape> render_shape;
};

/// What `reset` returns, and where `reset_into` writes.
struct ResetResult {
  /// The episode's first observation, laid out as observation_space().
  Value obs;
  /// What the env reports beside it; often empty.
  Info info;
};

/// What `step` returns, and where `step_into` writes. `terminated`: the task's own end (goal
/// reached, pole fell); `truncated`: cut off from outside the task (a time limit).
struct StepResult {
  /// The observation after the step, laid out as observation_space().
  Value obs;
  /// The step's reward (a pixel task with action_repeat sums its control steps' rewards).
  double reward = 0.0;
  bool terminated = false;
  bool truncated = false;
  /// What the env reports beside it; often empty.
  Info info;
};

/// Which call an observation buffer is for (see Env::observation_buffer): `reset` or `step`.
enum class BufferFor : std::uint8_t { kReset, kStep };

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

  /// Starts an episode; the observation is `observation_buffer(BufferFor::kReset)` filled by
  /// `reset_into`. Throws ResetNeeded after `close()`.
  ResetResult reset(std::optional<std::uint64_t> seed = std::nullopt, const Options& options = {});
  /// Advances one step; the observation is `observation_buffer(BufferFor::kStep)` filled by
  /// `step_into`: later calls never change it (it may share read-only memory with other
  /// observations, as FrameStackObservation's stacked frames do). Throws ResetNeeded when called
  /// out of order and std::invalid_argument when `action` is not in `action_space()` (naming the
  /// space and the value).
  StepResult step(const Value& action);

  /// The buffer that `reset()` (kReset) or `step()` (kStep) passes to `reset_into` /
  /// `step_into` and then returns, laid out as `observation_space()`. The default is
  /// `observation_space().zeros()`. An env may instead hand out memory of its own that the next
  /// call fills without copying, provided it never writes that memory again once returned
  /// (observations returned earlier never change) and `reset_into` / `step_into` still accept
  /// any other buffer laid out as the space. FrameStackObservation returns a view of its frame
  /// tape where the next stacked window will be, so that consecutive observations share their
  /// frames. Wrapper forwards the call to the inner env (a wrapper that leaves observations
  /// alone keeps that sharing); ObservationWrapper returns its own space's zeros(). Calling it
  /// changes no observation; it may be called at any time.
  virtual Value observation_buffer(BufferFor call);

  /// The buffer path, which `reset` and `step` also take after allocating `out.obs`: the
  /// observation is written into the arrays of `out.obs`, memory the caller owns and laid out as
  /// `observation_space()` (make one with `observation_space().zeros()`, or view a slot of a
  /// batch); `reward`, the flags and `info` are overwritten. Nothing is allocated on this path
  /// once the env is warmed up (pixel tasks; wrappers keep their own buffers). The env keeps no
  /// reference to `out`. Throws as `reset` / `step` do, and std::invalid_argument when `out.obs`
  /// is not laid out as `observation_space()`.
  void reset_into(ResetResult& out, std::optional<std::uint64_t> seed = std::nullopt,
                  const Options& options = {});
  /// The buffer path of `step`, as reset_into is of `reset`.
  void step_into(const Value& action, StepResult& out);
  /// The current frame as an (H, W, 3) uint8 array (render mode "rgb_array"). Throws
  /// ResetNeeded before the first `reset` or after `close`.
  Array render();
  /// Releases the env's resources. Calling it again does nothing.
  void close();

  /// The space every observation is in; the same object for the env's life.
  virtual const Space& observation_space() const = 0;
  /// The space `step` checks actions against; the same object for the env's life.
  virtual const Space& action_space() const = 0;
  /// What the env renders, and at what rate.
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

  /// Starts an episode, writing the observation into the arrays of `out.obs` (laid out as
  /// `observation_space()`; `out.info` is empty). `rng()` is already seeded. `seed` is passed on
  /// so that wrappers can forward it to the env they wrap.
  virtual void do_reset(std::optional<std::uint64_t> seed, const Options& options,
                        ResetResult& out) = 0;
  /// Advances one step with an action already known to be in `action_space()`, writing into
  /// `out` as do_reset does (`out.reward` is 0, the flags false and `out.info` empty on entry).
  virtual void do_step(const Value& action, StepResult& out) = 0;
  /// The current frame for `render()`, called only between reset and close: a new (H, W, 3)
  /// uint8 array.
  virtual Array do_render() = 0;
  /// Releases what the env holds; called at most once, by the first `close()`.
  virtual void do_close() {}

 private:
  std::shared_ptr<const EnvSpec> spec_;
  std::optional<Rng> rng_;
  bool has_reset_ = false;
  bool episode_over_ = false;
  bool closed_ = false;
};

}  // namespace pixelgym
