// Space: the set of valid observations or actions, as in gymnasium.spaces.Space.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "pixelgym/envs/array.h"
#include "pixelgym/envs/rng.h"
#include "pixelgym/envs/value.h"

namespace pixelgym {

/// Base of every space. Spaces are immutable after construction except for the generator that
/// the argument-less `sample()` uses, which `seed()` resets (as Gymnasium's `space.seed`). That
/// generator makes sampling through one space object not thread-safe; `sample(rng)` with a
/// generator of your own is.
class Space {
 public:
  virtual ~Space() = default;

  /// A random element of this space drawn from `rng`.
  virtual Value sample(Rng& rng) const = 0;
  /// A random element drawn from this space's own generator (seeded from entropy unless
  /// `seed()` was called).
  Value sample() const;
  /// Reseeds this space's own generator; returns the seed used (drawn from entropy when none is
  /// given).
  std::uint64_t seed(std::optional<std::uint64_t> seed = std::nullopt) const;
  /// The state of that generator (Rng::state), or std::nullopt while it was neither seeded nor
  /// used; with set_generator_state, what a copy of the space (Python's pickle and deepcopy) keeps
  /// so that it samples as the original would.
  std::optional<std::array<std::uint64_t, 4>> generator_state() const;
  /// Puts that generator in `state` (std::nullopt: unseeded, as a new space). Throws as
  /// Rng::from_state.
  void set_generator_state(const std::optional<std::array<std::uint64_t, 4>>& state) const;

  /// True when `value` is an element of this space: right structure, dtype, shape and bounds.
  bool contains(const Value& value) const { return mismatch(value).empty(); }
  /// Why `value` is not an element ("dtype float32, expected int64"), or "" when it is.
  virtual std::string mismatch(const Value& value) const = 0;

  /// A zero-filled Value laid out as an element of this space (structure, dtypes, shapes): the
  /// buffer that Env::reset_into / step_into write into. Not always an element itself
  /// (Discrete(3, start=1) holds no 0).
  virtual Value zeros() const;
  /// Why `value` is not laid out as an element of this space (structure, dtype, shape; the
  /// values themselves are not looked at), or "" when it is; allocates nothing when it is.
  virtual std::string layout_mismatch(const Value& value) const;

  /// The shape of an element; std::nullopt for Dict and Tuple spaces (as in Gymnasium).
  virtual std::optional<Shape> shape() const = 0;
  /// The dtype of an element; std::nullopt for Dict and Tuple spaces.
  virtual std::optional<DType> dtype() const = 0;
  /// Gymnasium's notation: "Box(-1.0, 1.0, (1,), float32)", "Discrete(4)".
  virtual std::string to_string() const = 0;
  /// Same kind and same parameters (bounds, sizes, keys...).
  virtual bool equals(const Space& other) const = 0;

 protected:
  Space() = default;
  Space(const Space&) = default;
  Space& operator=(const Space&) = default;

 private:
  mutable std::optional<Rng> rng_;
};

/// Spaces are shared, never copied: a Dict space holds its subspaces this way.
using SpacePtr = std::shared_ptr<const Space>;

/// Why `value` is not an array of `dtype` and `shape`, or "" (allocating nothing) when it is; for
/// the `layout_mismatch` of spaces whose elements are arrays.
std::string array_layout_mismatch(const Value& value, DType dtype, const Shape& shape);

/// Throws std::invalid_argument "<context>: <value> is not in <space>: <reason>" unless `space`
/// contains `value`.
void require_contains(const Space& space, const Value& value, const std::string& context);

}  // namespace pixelgym
