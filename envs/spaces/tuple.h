// spaces::Tuple: a fixed sequence of subspaces, as gymnasium.spaces.Tuple.
#pragma once

#include <vector>

#include "pixelgym/envs/space.h"

namespace pixelgym::spaces {

/// Elements are pixelgym::ValueTuple values of the same length, item i in subspace i.
class Tuple final : public Space {
 public:
  /// Throws std::invalid_argument for a null subspace.
  explicit Tuple(std::vector<SpacePtr> spaces);

  using Space::sample;
  Value sample(Rng& rng) const override;
  std::string mismatch(const Value& value) const override;
  Value zeros() const override;
  std::string layout_mismatch(const Value& value) const override;
  std::optional<Shape> shape() const override { return std::nullopt; }
  std::optional<DType> dtype() const override { return std::nullopt; }
  std::string to_string() const override;
  bool equals(const Space& other) const override;

  /// The subspaces, in order.
  const std::vector<SpacePtr>& spaces() const { return spaces_; }

 private:
  std::vector<SpacePtr> spaces_;
};

}  // namespace pixelgym::spaces
