#include "pixelgym/envs/spaces/box.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace pixelgym::spaces {
namespace {

std::string format_bound(double bound) {
  std::ostringstream out;
  if (std::isinf(bound)) return bound > 0 ? "inf" : "-inf";
  out << bound;
  std::string text = out.str();
  if (text.find_first_of(".e") == std::string::npos) text += ".0";
  return text;
}

std::string format_bounds(const std::vector<double>& bounds) {
  const bool uniform =
      std::all_of(bounds.begin(), bounds.end(), [&](double b) { return b == bounds.front(); });
  if (uniform && !bounds.empty()) return format_bound(bounds.front());
  constexpr std::size_t kMaxPrinted = 8;
  std::string text = "[";
  for (std::size_t i = 0; i < bounds.size() && i < kMaxPrinted; ++i) {
    if (i > 0) text += ", ";
    text += format_bound(bounds[i]);
  }
  if (bounds.size() > kMaxPrinted) text += ", ...";
  return text + "]";
}

// A bound of an integer Box as an int64. int64's own limits, held as doubles, are -2^63 and 2^63,
// and 2^63 is past int64: converting it was undefined (on x86 it gave INT64_MIN, so a Box over
// int64's whole range always drew INT64_MIN; found by fuzz/spaces_fuzz under UBSan).
std::int64_t integer_bound(double bound) {
  constexpr double kTwoTo63 = 9223372036854775808.0;
  if (bound >= kTwoTo63) return std::numeric_limits<std::int64_t>::max();
  return static_cast<std::int64_t>(bound);  // the constructor keeps bounds >= -2^63
}

template <typename T>
void fill_sample(const std::vector<double>& low, const std::vector<double>& high, Rng& rng,
                 T* out) {
  for (std::size_t i = 0; i < low.size(); ++i) {
    const bool has_low = std::isfinite(low[i]);
    const bool has_high = std::isfinite(high[i]);
    if constexpr (std::is_integral_v<T>) {
      out[i] = static_cast<T>(rng.integer(integer_bound(low[i]), integer_bound(high[i])));
    } else {
      double x;
      if (low[i] == high[i]) {
        x = low[i];  // one value, infinite ones included: Box(-inf, -inf) holds only -inf
      } else if (has_low && has_high) {
        x = rng.uniform(low[i], high[i]);
      } else if (has_low) {
        x = low[i] + rng.exponential();
      } else if (has_high) {
        x = high[i] - rng.exponential();
      } else {
        x = rng.normal();
      }
      // Rounding to float32 may step just outside the bounds; clamp back in.
      T value = static_cast<T>(x);
      if (has_low && value < low[i]) value = static_cast<T>(low[i]);
      if (has_high && value > high[i]) value = static_cast<T>(high[i]);
      out[i] = value;
    }
  }
}

}  // namespace

Box::Box(double low, double high, Shape shape, DType dtype)
    : Box(std::vector<double>(static_cast<std::size_t>(shape_size(shape)), low),
          std::vector<double>(static_cast<std::size_t>(shape_size(shape)), high), shape, dtype) {}

Box::Box(std::vector<double> low, std::vector<double> high, Shape shape, DType dtype)
    : low_(std::move(low)), high_(std::move(high)), shape_(std::move(shape)), dtype_(dtype) {
  const auto size = static_cast<std::size_t>(shape_size(shape_));
  const std::string where = "Box(" + shape_to_string(shape_) + ", " + dtype_name(dtype_) + ")";
  if (dtype_ == DType::kBool) {
    throw std::invalid_argument(where + ": bool is not a Box dtype; use MultiBinary");
  }
  if (low_.size() != size || high_.size() != size) {
    throw std::invalid_argument(where + ": low has " + std::to_string(low_.size()) + " and high " +
                                std::to_string(high_.size()) + " values, the shape needs " +
                                std::to_string(size));
  }
  for (std::size_t i = 0; i < size; ++i) {
    if (std::isnan(low_[i]) || std::isnan(high_[i])) {
      throw std::invalid_argument(where + ": bound " + std::to_string(i) + " is NaN");
    }
    if (is_integer(dtype_)) {
      const DTypeRange range = integer_range(dtype_);
      low_[i] = std::max(low_[i], range.low);
      high_[i] = std::min(high_[i], range.high);
      if (low_[i] != std::floor(low_[i]) || high_[i] != std::floor(high_[i]) ||
          low_[i] > range.high || high_[i] < range.low) {
        throw std::invalid_argument(where + ": bounds [" + format_bound(low_[i]) + ", " +
                                    format_bound(high_[i]) + "] of element " + std::to_string(i) +
                                    " are not integers within " + dtype_name(dtype_) + "'s range");
      }
    } else if (dtype_ == DType::kFloat32) {
      low_[i] = static_cast<float>(low_[i]);
      high_[i] = static_cast<float>(high_[i]);
    }
    if (low_[i] > high_[i]) {
      throw std::invalid_argument(where + ": low " + format_bound(low_[i]) + " > high " +
                                  format_bound(high_[i]) + " at element " + std::to_string(i));
    }
  }
}

bool Box::is_bounded() const {
  for (std::size_t i = 0; i < low_.size(); ++i) {
    if (!std::isfinite(low_[i]) || !std::isfinite(high_[i])) return false;
  }
  return true;
}

Value Box::sample(Rng& rng) const {
  Array array(dtype_, shape_);
  switch (dtype_) {
    case DType::kUInt8:
      fill_sample(low_, high_, rng, array.data<std::uint8_t>());
      break;
    case DType::kInt32:
      fill_sample(low_, high_, rng, array.data<std::int32_t>());
      break;
    case DType::kInt64:
      fill_sample(low_, high_, rng, array.data<std::int64_t>());
      break;
    case DType::kFloat32:
      fill_sample(low_, high_, rng, array.data<float>());
      break;
    case DType::kFloat64:
      fill_sample(low_, high_, rng, array.data<double>());
      break;
    case DType::kBool:
      break;  // rejected by the constructor
  }
  return array;
}

std::string Box::mismatch(const Value& value) const {
  if (!value.is_array()) return std::string("expected an array, got a ") + value.kind();
  const Array& array = value.array();
  if (array.dtype() != dtype_) {
    return std::string("dtype ") + dtype_name(array.dtype()) + ", expected " + dtype_name(dtype_);
  }
  if (array.shape() != shape_) {
    return "shape " + shape_to_string(array.shape()) + ", expected " + shape_to_string(shape_);
  }
  for (std::int64_t i = 0; i < array.size(); ++i) {
    const double x = array.element_as_double(i);
    const auto k = static_cast<std::size_t>(i);
    if (std::isnan(x)) return "element " + std::to_string(i) + " is NaN";
    if (x < low_[k] || x > high_[k]) {
      std::ostringstream out;
      out << "element " << i << " = " << x << " is outside [" << format_bound(low_[k]) << ", "
          << format_bound(high_[k]) << "]";
      return out.str();
    }
  }
  return "";
}

std::string Box::to_string() const {
  return "Box(" + format_bounds(low_) + ", " + format_bounds(high_) + ", " +
         shape_to_string(shape_) + ", " + dtype_name(dtype_) + ")";
}

bool Box::equals(const Space& other) const {
  const auto* box = dynamic_cast<const Box*>(&other);
  return box != nullptr && box->dtype_ == dtype_ && box->shape_ == shape_ && box->low_ == low_ &&
         box->high_ == high_;
}

}  // namespace pixelgym::spaces
