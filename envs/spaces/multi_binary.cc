#include "pixelgym/envs/spaces/multi_binary.h"

#include <stdexcept>

namespace pixelgym::spaces {

MultiBinary::MultiBinary(Shape shape) : shape_(std::move(shape)) { shape_size(shape_); }

Value MultiBinary::sample(Rng& rng) const {
  Array array(DType::kUInt8, shape_);
  auto* out = array.data<std::uint8_t>();
  for (std::int64_t i = 0; i < array.size(); ++i)
    out[i] = static_cast<std::uint8_t>(rng.integer(0, 1));
  return array;
}

std::string MultiBinary::mismatch(const Value& value) const {
  if (!value.is_array()) return std::string("expected a uint8 array, got a ") + value.kind();
  const Array& array = value.array();
  if (array.dtype() != DType::kUInt8 && array.dtype() != DType::kBool) {
    return std::string("dtype ") + dtype_name(array.dtype()) + ", expected uint8 (or bool)";
  }
  if (array.shape() != shape_) {
    return "shape " + shape_to_string(array.shape()) + ", expected " + shape_to_string(shape_);
  }
  for (std::int64_t i = 0; i < array.size(); ++i) {
    const double x = array.element_as_double(i);
    if (x != 0.0 && x != 1.0) {
      return "element " + std::to_string(i) + " = " + std::to_string(static_cast<int>(x)) +
             " is neither 0 nor 1";
    }
  }
  return "";
}

std::string MultiBinary::to_string() const {
  if (shape_.size() == 1) return "MultiBinary(" + std::to_string(shape_[0]) + ")";
  return "MultiBinary(" + shape_to_string(shape_) + ")";
}

bool MultiBinary::equals(const Space& other) const {
  const auto* binary = dynamic_cast<const MultiBinary*>(&other);
  return binary != nullptr && binary->shape_ == shape_;
}

}  // namespace pixelgym::spaces
