#include "pixelgym/wrappers/dtype_observation.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

namespace pixelgym::wrappers {
namespace {

std::string format(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

// One element, saturating as the header says.
template <typename To, typename From>
To convert(From x) {
  if constexpr (std::is_floating_point_v<To>) {
    return static_cast<To>(x);
  } else if constexpr (std::is_floating_point_v<From>) {
    if (std::isnan(x)) return To{0};
    const double t = std::trunc(static_cast<double>(x));
    // (double) max of int64 is 2^63, one past it: >= catches it.
    if (t <= static_cast<double>(std::numeric_limits<To>::min())) {
      return std::numeric_limits<To>::min();
    }
    if (t >= static_cast<double>(std::numeric_limits<To>::max())) {
      return std::numeric_limits<To>::max();
    }
    return static_cast<To>(t);
  } else {
    // uint8, int32 and int64 all fit in int64.
    const auto v = static_cast<std::int64_t>(x);
    const auto low = static_cast<std::int64_t>(std::numeric_limits<To>::min());
    const auto high = static_cast<std::int64_t>(std::numeric_limits<To>::max());
    return static_cast<To>(v < low ? low : v > high ? high : v);
  }
}

template <typename To, typename From>
void convert_all(const Array& in, Array& out) {
  const From* from = in.data<From>();
  To* to = out.data<To>();
  for (std::int64_t i = 0; i < in.size(); ++i) to[i] = convert<To, From>(from[i]);
}

template <typename To>
void convert_from(const Array& in, Array& out) {
  switch (in.dtype()) {
    case DType::kUInt8:
      return convert_all<To, std::uint8_t>(in, out);
    case DType::kInt32:
      return convert_all<To, std::int32_t>(in, out);
    case DType::kInt64:
      return convert_all<To, std::int64_t>(in, out);
    case DType::kFloat32:
      return convert_all<To, float>(in, out);
    case DType::kFloat64:
      return convert_all<To, double>(in, out);
    case DType::kBool:
      break;
  }
  throw std::runtime_error("DtypeObservation: a bool observation (not a Box dtype)");
}

}  // namespace

DtypeObservation::DtypeObservation(std::unique_ptr<Env> env, DType dtype, const std::string& key)
    : ObservationWrapper(std::move(env)), dtype_(dtype) {
  if (dtype == DType::kBool) {
    throw std::invalid_argument(
        "DtypeObservation: dtype must be uint8, int32, int64, float32 or float64, got bool (not a "
        "Box dtype)");
  }
  const Space& inner = env_->observation_space();
  where_ = find_box(inner, key, "DtypeObservation");
  const spaces::Box& box = *where_.box;
  const DType source = *box.dtype();
  std::vector<double> low = box.low();
  std::vector<double> high = box.high();
  if (is_integer(dtype)) {
    const DTypeRange target = integer_range(dtype);
    const DTypeRange own =
        is_integer(source) ? integer_range(source) : DTypeRange{-HUGE_VAL, HUGE_VAL};
    const auto bound = [&](double value, bool is_low, std::size_t i) {
      // Unbounded on this side: the target's limit.
      if (is_low ? value <= own.low : value >= own.high) return is_low ? target.low : target.high;
      const double t = std::trunc(value);
      if (t < target.low || t > target.high) {
        throw std::invalid_argument(
            "DtypeObservation: " + std::string(is_low ? "low" : "high") + " bound " +
            format(value) + " of element " + std::to_string(i) + " of " + box.to_string() +
            (key.empty() ? "" : " (key \"" + key + "\")") + " is outside " + dtype_name(dtype) +
            "'s range [" + format(target.low) + ", " + format(target.high) +
            "]; clip the observation first or pick a wider dtype");
      }
      return t;
    };
    for (std::size_t i = 0; i < low.size(); ++i) {
      low[i] = bound(low[i], true, i);
      high[i] = bound(high[i], false, i);
    }
  }
  set_observation_space(replace_box(
      inner, where_,
      std::make_shared<spaces::Box>(std::move(low), std::move(high), *box.shape(), dtype)));
}

void DtypeObservation::observation(const Value& in, Value& out) {
  const Array& x = box_of(in, where_);
  Array& y = box_of(out, where_);
  switch (dtype_) {
    case DType::kUInt8:
      convert_from<std::uint8_t>(x, y);
      break;
    case DType::kInt32:
      convert_from<std::int32_t>(x, y);
      break;
    case DType::kInt64:
      convert_from<std::int64_t>(x, y);
      break;
    case DType::kFloat32:
      convert_from<float>(x, y);
      break;
    case DType::kFloat64:
      convert_from<double>(x, y);
      break;
    case DType::kBool:
      break;  // refused in the constructor
  }
  copy_other_entries(in, out, where_);
}

}  // namespace pixelgym::wrappers
