// Batched spaces and batch slots: gymnasium.vector.utils' batch_space, iterate and concatenate,
// for Values that live in one preallocated batch.
#pragma once

#include <cstdint>
#include <string>

#include "pixelgym/envs/space.h"
#include "pixelgym/envs/value.h"

namespace pixelgym::vector {

/// The space of `n` elements of `space` stacked along a new leading axis, as Gymnasium's
/// `batch_space`: Box (S, dtype) -> Box (n, *S) with the bounds repeated; Discrete(k, start) ->
/// MultiDiscrete([k] * n, start=[start] * n); MultiDiscrete (S) -> an int64 Box (n, *S) from start
/// to start + nvec - 1; MultiBinary (S) -> a uint8 Box(0, 1, (n, *S)); Dict and Tuple -> the same
/// structure of batched subspaces. Throws std::invalid_argument for n < 1 or a space of another
/// kind (naming it).
SpacePtr batch_space(const Space& space, std::int64_t n);

/// Row `i` of every array in `batch` (a Value laid out as a batched space), as views sharing its
/// memory: what env `i` reads its action from or writes its observation into. Allocates the
/// Dict / Tuple structure (call it once per slot, not per step). Throws std::out_of_range.
Value batch_slot(const Value& batch, std::int64_t i);

/// Copies the arrays of `source` into those of `destination` (the same structure, dtypes and
/// shapes; see Space::layout_mismatch), allocating nothing. Throws std::invalid_argument on a
/// mismatch.
void copy_value(const Value& source, const Value& destination);

/// Sets every byte of every array in `value` to zero, allocating nothing.
void zero_value(const Value& value);

}  // namespace pixelgym::vector
