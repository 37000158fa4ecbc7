#include "pixelgym/envs/spaces/multi_discrete.h"

#include <limits>
#include <stdexcept>

namespace pixelgym::spaces {
namespace {

std::string join(const std::vector<std::int64_t>& values) {
  std::string text = "[";
  for (std::size_t i = 0; i < values.size(); ++i) {
    text += (i > 0 ? ", " : "") + std::to_string(values[i]);
  }
  return text + "]";
}

}  // namespace

MultiDiscrete::MultiDiscrete(std::vector<std::int64_t> nvec, std::vector<std::int64_t> start,
                             std::optional<Shape> shape)
    : nvec_(std::move(nvec)),
      start_(std::move(start)),
      shape_(shape ? *shape : Shape{static_cast<std::int64_t>(nvec_.size())}) {
  if (start_.empty()) start_.assign(nvec_.size(), 0);
  if (static_cast<std::int64_t>(nvec_.size()) != shape_size(shape_) ||
      start_.size() != nvec_.size()) {
    throw std::invalid_argument("MultiDiscrete: nvec has " + std::to_string(nvec_.size()) +
                                " entries and start " + std::to_string(start_.size()) + "; shape " +
                                shape_to_string(shape_) + " needs " +
                                std::to_string(shape_size(shape_)));
  }
  for (std::size_t i = 0; i < nvec_.size(); ++i) {
    if (nvec_[i] <= 0) {
      throw std::invalid_argument("MultiDiscrete: nvec must be positive, got " + join(nvec_));
    }
    // start + nvec - 1, the largest value of an entry, must be an int64 (as Discrete's).
    if (start_[i] > std::numeric_limits<std::int64_t>::max() - (nvec_[i] - 1)) {
      throw std::invalid_argument(
          "MultiDiscrete: start + nvec - 1 must fit in int64, got start = " + join(start_) +
          ", nvec = " + join(nvec_) + " (entry " + std::to_string(i) + ")");
    }
  }
}

Value MultiDiscrete::sample(Rng& rng) const {
  Array array(DType::kInt64, shape_);
  auto* out = array.data<std::int64_t>();
  for (std::size_t i = 0; i < nvec_.size(); ++i) out[i] = start_[i] + rng.integer(0, nvec_[i] - 1);
  return array;
}

std::string MultiDiscrete::mismatch(const Value& value) const {
  if (!value.is_array()) return std::string("expected an integer array, got a ") + value.kind();
  const Array& array = value.array();
  if (!is_integer(array.dtype())) {
    return std::string("dtype ") + dtype_name(array.dtype()) + ", expected an integer dtype";
  }
  if (array.shape() != shape_) {
    return "shape " + shape_to_string(array.shape()) + ", expected " + shape_to_string(shape_);
  }
  for (std::int64_t i = 0; i < array.size(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    const std::int64_t x = array.element_as_int64(i);  // exactly: not through a double
    if (x < start_[k] || x > start_[k] + (nvec_[k] - 1)) {
      return "element " + std::to_string(i) + " = " + std::to_string(x) + " is outside {" +
             std::to_string(start_[k]) + ", ..., " + std::to_string(start_[k] + (nvec_[k] - 1)) +
             "}";
    }
  }
  return "";
}

std::string MultiDiscrete::to_string() const {
  bool zero_start = true;
  for (std::int64_t s : start_) zero_start = zero_start && s == 0;
  return "MultiDiscrete(" + join(nvec_) + (zero_start ? "" : ", start=" + join(start_)) + ")";
}

bool MultiDiscrete::equals(const Space& other) const {
  const auto* multi = dynamic_cast<const MultiDiscrete*>(&other);
  return multi != nullptr && multi->nvec_ == nvec_ && multi->start_ == start_ &&
         multi->shape_ == shape_;
}

}  // namespace pixelgym::spaces
