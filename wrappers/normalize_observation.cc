#include "pixelgym/wrappers/normalize_observation.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace pixelgym::wrappers {
namespace {

template <typename T>
void normalize(const Array& in, Array& out, RunningStatistics& statistics, bool update,
               double epsilon) {
  const T* x = in.data<T>();
  if (update) statistics.update([x](std::size_t i) { return static_cast<double>(x[i]); });
  float* y = out.data<float>();
  const std::size_t size = statistics.mean.size();
  for (std::size_t i = 0; i < size; ++i) {
    y[i] = static_cast<float>((static_cast<double>(x[i]) - statistics.mean[i]) /
                              std::sqrt(statistics.var[i] + epsilon));
  }
}

}  // namespace

NormalizeObservation::NormalizeObservation(std::unique_ptr<Env> env, const std::string& key,
                                           double epsilon)
    : ObservationWrapper(std::move(env)), epsilon_(epsilon) {
  if (!std::isfinite(epsilon) || !(epsilon > 0.0)) {
    std::ostringstream text;
    text << "NormalizeObservation: epsilon must be finite and > 0, got " << epsilon;
    throw std::invalid_argument(text.str());
  }
  const Space& inner = env_->observation_space();
  where_ = find_box(inner, key, "NormalizeObservation");
  const Shape shape = *where_.box->shape();
  statistics_ = RunningStatistics::initial(static_cast<std::size_t>(shape_size(shape)));
  const double inf = std::numeric_limits<double>::infinity();
  set_observation_space(
      replace_box(inner, where_, std::make_shared<spaces::Box>(-inf, inf, shape, DType::kFloat32)));
}

void NormalizeObservation::set_statistics(RunningStatistics statistics) {
  const std::string reason = statistics.invalid_reason(statistics_.mean.size());
  if (!reason.empty()) {
    throw std::invalid_argument("NormalizeObservation: statistics for " +
                                std::to_string(statistics_.mean.size()) +
                                " elements expected: " + reason);
  }
  statistics_ = std::move(statistics);
}

void NormalizeObservation::observation(const Value& in, Value& out) {
  const Array& x = box_of(in, where_);
  Array& y = box_of(out, where_);
  switch (x.dtype()) {
    case DType::kUInt8:
      normalize<std::uint8_t>(x, y, statistics_, update_statistics_, epsilon_);
      break;
    case DType::kInt32:
      normalize<std::int32_t>(x, y, statistics_, update_statistics_, epsilon_);
      break;
    case DType::kInt64:
      normalize<std::int64_t>(x, y, statistics_, update_statistics_, epsilon_);
      break;
    case DType::kFloat32:
      normalize<float>(x, y, statistics_, update_statistics_, epsilon_);
      break;
    case DType::kFloat64:
      normalize<double>(x, y, statistics_, update_statistics_, epsilon_);
      break;
    case DType::kBool:
      throw std::runtime_error("NormalizeObservation: a bool observation (not a Box dtype)");
  }
  copy_other_entries(in, out, where_);
}

}  // namespace pixelgym::wrappers
