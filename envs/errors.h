// The exceptions pixelgym throws, and what a language binding maps each to.
#pragma once

#include <stdexcept>

namespace pixelgym {

// Every error pixelgym reports is one of these standard or pixelgym exception types; the message
// names the component, what it expected and what it was given. A binding maps them by type,
// without reading messages:
//
// - std::out_of_range: a missing key or position (a ValueDict or spaces::Dict key, an Array
//   index or slice, a Dict-space insert position, a Task's state name, a World robot or body
//   id). Python: KeyError for keys, IndexError for positions.
// - std::invalid_argument: a bad value from the caller (an action not in the action space, an
//   unknown env id or kwarg, a kwarg of the wrong type, a buffer of the wrong layout, a bad
//   config). Python: ValueError.
// - ResetNeeded: calls out of order (step or render before reset, step after the episode
//   ended, anything but close after close). Python: gymnasium.error.ResetNeeded, or
//   RuntimeError without gymnasium.
// - std::runtime_error: the environment failing, not the caller (a file that cannot be read or
//   written, a GL context that cannot be made; a URDF or mesh that cannot be used, as
//   engine::UrdfError). Python: RuntimeError.
// - PhysicsDivergence (a std::runtime_error): a simulation that went non-finite. Python:
//   RuntimeError.
//
// std::out_of_range and std::invalid_argument both derive from std::logic_error, and so does
// ResetNeeded: catch ResetNeeded before std::logic_error when the difference matters.

/// Thrown for calls in the wrong order: `step` or `render` before the first `reset`, `step` after
/// the episode ended without a new `reset`, anything but `close` after `close`. (Gymnasium's
/// `ResetNeeded`.)
class ResetNeeded : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

/// Thrown by an env whose simulation diverged: a state, observation or reward that is not finite
/// (an absurd force, a stiff setting). The message names the env, the step of the episode and what
/// went non-finite; the episode is over, and reset() starts a new one. An env never returns a
/// non-finite observation or reward instead.
class PhysicsDivergence : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace pixelgym
