// spaces::Discrete: integers {start, ..., start + n - 1}, as gymnasium.spaces.Discrete.
#pragma once

#include "pixelgym/envs/space.h"

namespace pixelgym::spaces {

/// Elements are 0-dimensional integer arrays; `sample` gives int64, `contains` accepts any
/// integer dtype (uint8, int32, int64), as Gymnasium accepts any numpy integer.
class Discrete final : public Space {
 public:
  /// Throws std::invalid_argument unless n > 0 and start + n - 1 fits in an int64.
  explicit Discrete(std::int64_t n, std::int64_t start = 0);

  using Space::sample;
  Value sample(Rng& rng) const override;
  std::string mismatch(const Value& value) const override;
  std::optional<Shape> shape() const override { return Shape{}; }
  std::optional<DType> dtype() const override { return DType::kInt64; }
  std::string to_string() const override;
  bool equals(const Space& other) const override;

  /// The number of elements.
  std::int64_t n() const { return n_; }
  /// The smallest element.
  std::int64_t start() const { return start_; }

 private:
  std::int64_t n_;
  std::int64_t start_;
};

}  // namespace pixelgym::spaces
