// spaces::Box: a (possibly unbounded) box in R^n or Z^n, as gymnasium.spaces.Box.
#pragma once

#include <vector>

#include "pixelgym/envs/space.h"

namespace pixelgym::spaces {

/// Arrays of one shape and dtype whose every element lies in [low, high].
///
/// Bounds are stored as doubles already rounded to the dtype; infinite bounds are allowed for
/// float dtypes and mean "unbounded" on that side; for integer dtypes they are clamped to the
/// dtype's range. (int64 bounds beyond 2^53 lose precision.) Sampling follows Gymnasium:
/// uniform on a bounded interval, normal when unbounded, a shifted exponential when bounded on
/// one side; integers uniformly in [low, high] inclusive.
class Box final : public Space {
 public:
  /// The same bounds for every element. Throws std::invalid_argument for a bool dtype, NaN
  /// bounds, low > high (after rounding to the dtype), or, for an integer dtype, bounds that are
  /// not whole numbers or leave no value of the dtype's range (bounds partly beyond it are
  /// clamped).
  Box(double low, double high, Shape shape, DType dtype = DType::kFloat32);
  /// Per-element bounds in row-major order; each vector has shape_size(shape) entries. Throws as
  /// above, and std::invalid_argument for a vector of another size.
  Box(std::vector<double> low, std::vector<double> high, Shape shape,
      DType dtype = DType::kFloat32);

  using Space::sample;
  Value sample(Rng& rng) const override;
  std::string mismatch(const Value& value) const override;
  std::optional<Shape> shape() const override { return shape_; }
  std::string layout_mismatch(const Value& value) const override {
    return array_layout_mismatch(value, dtype_, shape_);
  }
  std::optional<DType> dtype() const override { return dtype_; }
  std::string to_string() const override;
  bool equals(const Space& other) const override;

  /// The lower bound of each element, row-major, as stored (rounded or clamped to the dtype).
  const std::vector<double>& low() const { return low_; }
  /// The upper bound of each element, row-major, as stored.
  const std::vector<double>& high() const { return high_; }
  /// True when every element is bounded below and above.
  bool is_bounded() const;

 private:
  std::vector<double> low_;
  std::vector<double> high_;
  Shape shape_;
  DType dtype_;
};

}  // namespace pixelgym::spaces
