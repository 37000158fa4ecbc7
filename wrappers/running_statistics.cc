#include "pixelgym/wrappers/running_statistics.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace pixelgym::wrappers {
namespace {

std::string format(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

std::string vector_reason(const std::vector<double>& values, const char* name, std::size_t size,
                          bool non_negative) {
  if (values.size() != size) {
    return std::string(name) + " has " + std::to_string(values.size()) + " entries, expected " +
           std::to_string(size);
  }
  for (std::size_t i = 0; i < values.size(); ++i) {
    const std::string where = std::string(name) + "[" + std::to_string(i) + "] is ";
    if (!std::isfinite(values[i])) return where + format(values[i]) + ", must be finite";
    if (non_negative && values[i] < 0.0) return where + format(values[i]) + ", must be >= 0";
  }
  return "";
}

// The float64 array under `key` of a statistics Dict, of `shape`; throws naming `context`.
const Array& entry(const ValueDict& dict, const char* key, const Shape& shape,
                   const std::string& context) {
  if (!dict.contains(key) || !dict.at(key).is_array()) {
    throw std::invalid_argument(context + ": statistics need an array under \"" + key + "\"");
  }
  const Array& array = dict.at(key).array();
  if (array.dtype() != DType::kFloat64 || array.shape() != shape) {
    throw std::invalid_argument(context + ": statistics \"" + key + "\" must be float64 " +
                                shape_to_string(shape) + ", got " + dtype_name(array.dtype()) +
                                " " + shape_to_string(array.shape()));
  }
  return array;
}

}  // namespace

RunningStatistics RunningStatistics::initial(std::size_t size) {
  RunningStatistics statistics;
  statistics.mean.assign(size, 0.0);
  statistics.var.assign(size, 1.0);
  statistics.count = kInitialCount;
  return statistics;
}

std::string RunningStatistics::invalid_reason(std::size_t size) const {
  std::string reason = vector_reason(mean, "mean", size, false);
  if (reason.empty()) reason = vector_reason(var, "var", size, true);
  if (reason.empty() && !(std::isfinite(count) && count > 0.0)) {
    reason = "count is " + format(count) + ", must be finite and > 0";
  }
  return reason;
}

Value RunningStatistics::to_value() const {
  const auto size = static_cast<std::int64_t>(mean.size());
  return ValueDict{{"mean", Array::from_vector<double>({size}, mean)},
                   {"var", Array::from_vector<double>({size}, var)},
                   {"count", Array::scalar<double>(count)}};
}

RunningStatistics RunningStatistics::from_value(const Value& value, std::size_t size,
                                                const std::string& context) {
  if (!value.is_dict()) {
    throw std::invalid_argument(context + ": statistics must be a Dict{\"mean\", \"var\", " +
                                "\"count\"}, got " + value.kind());
  }
  const ValueDict& dict = value.dict();
  if (dict.size() != 3) {
    throw std::invalid_argument(context + ": statistics must have exactly the keys \"mean\", " +
                                "\"var\" and \"count\", got " + value.to_string());
  }
  const Shape shape = {static_cast<std::int64_t>(size)};
  const Array& mean = entry(dict, "mean", shape, context);
  const Array& var = entry(dict, "var", shape, context);
  const Array& count = entry(dict, "count", {}, context);
  RunningStatistics statistics;
  statistics.mean.assign(mean.data<double>(), mean.data<double>() + size);
  statistics.var.assign(var.data<double>(), var.data<double>() + size);
  statistics.count = count.item<double>();
  const std::string reason = statistics.invalid_reason(size);
  if (!reason.empty()) throw std::invalid_argument(context + ": invalid statistics: " + reason);
  return statistics;
}

}  // namespace pixelgym::wrappers
