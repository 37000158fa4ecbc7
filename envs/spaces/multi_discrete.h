// spaces::MultiDiscrete: one Discrete per element, as gymnasium.spaces.MultiDiscrete.
#pragma once

#include <vector>

#include "pixelgym/envs/space.h"

namespace pixelgym::spaces {

/// int64 arrays whose element i lies in {start[i], ..., start[i] + nvec[i] - 1}.
class MultiDiscrete final : public Space {
 public:
  /// `nvec` in row-major order for `shape` (default: a vector of nvec.size() elements); `start`
  /// defaults to zeros. Throws std::invalid_argument for a non-positive entry or a size mismatch.
  explicit MultiDiscrete(std::vector<std::int64_t> nvec, std::vector<std::int64_t> start = {},
                         std::optional<Shape> shape = std::nullopt);

  using Space::sample;
  Value sample(Rng& rng) const override;
  std::string mismatch(const Value& value) const override;
  std::optional<Shape> shape() const override { return shape_; }
  std::string layout_mismatch(const Value& value) const override {
    return array_layout_mismatch(value, DType::kInt64, shape_);
  }
  std::optional<DType> dtype() const override { return DType::kInt64; }
  std::string to_string() const override;
  bool equals(const Space& other) const override;

  /// The number of values of each element, row-major.
  const std::vector<std::int64_t>& nvec() const { return nvec_; }
  /// The smallest value of each element, row-major.
  const std::vector<std::int64_t>& start() const { return start_; }

 private:
  std::vector<std::int64_t> nvec_;
  std::vector<std::int64_t> start_;
  Shape shape_;
};

}  // namespace pixelgym::spaces
