// spaces::MultiBinary: arrays of 0s and 1s, as gymnasium.spaces.MultiBinary.
#pragma once

#include "pixelgym/envs/space.h"

namespace pixelgym::spaces {

/// uint8 arrays of a fixed shape whose elements are 0 or 1 (Gymnasium uses int8, which Array does
/// not have; uint8 holds the same values). `contains` also accepts bool arrays.
class MultiBinary final : public Space {
 public:
  /// `MultiBinary({n})` is Gymnasium's `MultiBinary(n)`. Throws std::invalid_argument for a
  /// negative extent.
  explicit MultiBinary(Shape shape);

  using Space::sample;
  Value sample(Rng& rng) const override;
  std::string mismatch(const Value& value) const override;
  std::optional<Shape> shape() const override { return shape_; }
  std::string layout_mismatch(const Value& value) const override {
    return array_layout_mismatch(value, DType::kUInt8, shape_);
  }
  std::optional<DType> dtype() const override { return DType::kUInt8; }
  std::string to_string() const override;
  bool equals(const Space& other) const override;

 private:
  Shape shape_;
};

}  // namespace pixelgym::spaces
