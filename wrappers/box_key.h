// The part the non-image observation wrappers share (NormalizeObservation, DtypeObservation):
// finding the Box they transform — the bare Box observation, or one key of a spaces::Dict.
#pragma once

#include <cstddef>
#include <string>

#include "pixelgym/envs/array.h"
#include "pixelgym/envs/space.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/value.h"

namespace pixelgym::wrappers {

/// Where a wrapper's Box is in an observation.
struct BoxKey {
  /// The key; empty when the observation space is a bare Box.
  std::string key;
  /// True when the observation space is a spaces::Dict.
  bool in_dict = false;
  /// Position of `key` among the Dict's entries (0 for a bare Box).
  std::size_t index = 0;
  /// The Box itself (owned by the inner env's observation space, which outlives the wrapper's
  /// use of it: it is only read in the wrapper's constructor).
  const spaces::Box* box = nullptr;
};

/// Finds the Box `key` in `space` for `wrapper` (its class name, used in messages): with an empty
/// key the space must be a Box; with a key it must be a spaces::Dict whose entry `key` is a Box.
/// Throws std::invalid_argument naming the wrapper and the key, what was expected and what was
/// found, and listing the Dict's Box keys.
BoxKey find_box(const Space& space, const std::string& key, const std::string& wrapper);

/// The observation space with the Box replaced by `box_space`: `box_space` itself for a bare Box,
/// else the Dict with that one entry replaced.
SpacePtr replace_box(const Space& space, const BoxKey& where, SpacePtr box_space);

/// The Box's array in an observation laid out as the space `where` was found in.
const Array& box_of(const Value& observation, const BoxKey& where);
Array& box_of(Value& observation, const BoxKey& where);

/// Copies every entry of `in` but the Box into the matching arrays of `out` (no allocation);
/// nothing for a bare Box.
void copy_other_entries(const Value& in, Value& out, const BoxKey& where);

}  // namespace pixelgym::wrappers
