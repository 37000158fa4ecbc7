#include "pixelgym/envs/space.h"

#include <stdexcept>

namespace pixelgym {

Value Space::sample() const {
  if (!rng_) seed();
  return sample(*rng_);
}

std::uint64_t Space::seed(std::optional<std::uint64_t> seed) const {
  const std::uint64_t used = seed ? *seed : Rng::entropy_seed();
  rng_.emplace(used);
  return used;
}

std::optional<std::array<std::uint64_t, 4>> Space::generator_state() const {
  if (!rng_) return std::nullopt;
  return rng_->state();
}

void Space::set_generator_state(const std::optional<std::array<std::uint64_t, 4>>& state) const {
  if (state) {
    rng_ = Rng::from_state(*state);
  } else {
    rng_.reset();
  }
}

Value Space::zeros() const { return Array(*dtype(), *shape()); }

std::string Space::layout_mismatch(const Value& value) const {
  return array_layout_mismatch(value, *dtype(), *shape());
}

std::string array_layout_mismatch(const Value& value, DType dtype, const Shape& shape) {
  if (!value.is_array()) return std::string("expected an array, got a ") + value.kind();
  const Array& array = value.array();
  if (array.dtype() != dtype) {
    return std::string("dtype ") + dtype_name(array.dtype()) + ", expected " + dtype_name(dtype);
  }
  if (array.shape() != shape) {
    return "shape " + shape_to_string(array.shape()) + ", expected " + shape_to_string(shape);
  }
  return "";
}

void require_contains(const Space& space, const Value& value, const std::string& context) {
  const std::string reason = space.mismatch(value);
  if (!reason.empty()) {
    throw std::invalid_argument(context + ": " + value.to_string() + " is not in " +
                                space.to_string() + ": " + reason);
  }
}

}  // namespace pixelgym
