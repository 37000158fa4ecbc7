#include "pixelgym/wrappers/vector/normalize_observation.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "pixelgym/envs/spaces/box.h"

namespace pixelgym::vector {
namespace {

using wrappers::RunningStatistics;

// Calls `f(T{})` with T the C++ type of `dtype` (not bool).
template <typename F>
void with_type(DType dtype, F&& f) {
  switch (dtype) {
    case DType::kUInt8:
      f(std::uint8_t{});
      return;
    case DType::kInt32:
      f(std::int32_t{});
      return;
    case DType::kInt64:
      f(std::int64_t{});
      return;
    case DType::kFloat32:
      f(float{});
      return;
    case DType::kFloat64:
      f(double{});
      return;
    case DType::kBool:
      break;
  }
  throw std::invalid_argument("NormalizeObservation: cannot normalize a bool Box");
}

// The per-env wrapper's formula, element by element.
template <typename T>
void normalize_row(const T* x, float* y, const RunningStatistics& statistics, double epsilon) {
  for (std::size_t i = 0; i < statistics.mean.size(); ++i) {
    y[i] = static_cast<float>((static_cast<double>(x[i]) - statistics.mean[i]) /
                              std::sqrt(statistics.var[i] + epsilon));
  }
}

}  // namespace

NormalizeObservation::NormalizeObservation(std::unique_ptr<VectorEnv> env, const std::string& key,
                                           double epsilon)
    : VectorWrapper(std::move(env)), epsilon_(epsilon) {
  if (!std::isfinite(epsilon) || !(epsilon > 0.0)) {
    std::ostringstream text;
    text << "NormalizeObservation: epsilon must be finite and > 0, got " << epsilon;
    throw std::invalid_argument(text.str());
  }
  const Space& inner = single_observation_space();
  where_ = wrappers::find_box(inner, key, "NormalizeObservation");
  if (*where_.box->dtype() == DType::kBool) {
    throw std::invalid_argument("NormalizeObservation: key \"" + key +
                                "\" must be a Box of numbers, got " + where_.box->to_string());
  }
  const Shape shape = *where_.box->shape();
  row_size_ = static_cast<std::size_t>(shape_size(shape));
  statistics_ = RunningStatistics::initial(row_size_);
  const double inf = std::numeric_limits<double>::infinity();
  set_single_observation_space(wrappers::replace_box(
      inner, where_, std::make_shared<spaces::Box>(-inf, inf, shape, DType::kFloat32)));
  obs_ = observation_space().zeros();
  if (autoreset_mode() == AutoresetMode::kSameStep) final_obs_ = observation_space().zeros();
  reset_result_.obs = obs_;
  step_result_.obs = obs_;
  rows_.reserve(2 * static_cast<std::size_t>(num_envs()));
}

void NormalizeObservation::set_statistics(RunningStatistics statistics) {
  const std::string reason = statistics.invalid_reason(row_size_);
  if (!reason.empty()) {
    throw std::invalid_argument("NormalizeObservation: statistics for " +
                                std::to_string(row_size_) + " elements expected: " + reason);
  }
  statistics_ = std::move(statistics);
}

void NormalizeObservation::transform(const Array& in, const bool* in_mask, Array& out,
                                     const Array* final_in, const bool* final_mask,
                                     Array* final_out) {
  const auto rows = static_cast<std::size_t>(num_envs());
  with_type(in.dtype(), [&](auto tag) {
    using T = decltype(tag);
    const T* x = in.data<T>();
    const T* final_x = final_in != nullptr ? final_in->data<T>() : nullptr;
    rows_.clear();
    for (std::size_t r = 0; r < rows; ++r) {
      if (in_mask == nullptr || in_mask[r]) rows_.push_back(x + r * row_size_);
    }
    for (std::size_t r = 0; final_x != nullptr && r < rows; ++r) {
      if (final_mask[r]) rows_.push_back(final_x + r * row_size_);
    }
    if (update_statistics_) {
      statistics_.update_batch(rows_.size(), [this](std::size_t row, std::size_t i) {
        return static_cast<double>(static_cast<const T*>(rows_[row])[i]);
      });
    }
    float* y = out.data<float>();
    for (std::size_t r = 0; r < rows; ++r) {
      if (in_mask != nullptr && !in_mask[r]) continue;
      normalize_row(x + r * row_size_, y + r * row_size_, statistics_, epsilon_);
    }
    if (final_x == nullptr) return;
    float* final_y = final_out->data<float>();
    for (std::size_t r = 0; r < rows; ++r) {
      if (final_mask[r]) {
        normalize_row(final_x + r * row_size_, final_y + r * row_size_, statistics_, epsilon_);
      } else {
        std::memset(final_y + r * row_size_, 0, row_size_ * sizeof(float));
      }
    }
  });
}

const VectorResetResult& NormalizeObservation::do_reset(std::optional<std::uint64_t> seed,
                                                        const Options& options,
                                                        const Array* reset_mask) {
  const VectorResetResult& inner = reset_inner(seed, options, reset_mask);
  const bool* mask = reset_mask != nullptr ? reset_mask->data<bool>() : nullptr;
  transform(wrappers::box_of(inner.obs, where_), mask, wrappers::box_of(obs_, where_), nullptr,
            nullptr, nullptr);
  wrappers::copy_other_entries(inner.obs, obs_, where_);
  copy_infos(inner.infos, reset_result_.infos);
  return reset_result_;
}

const VectorStepResult& NormalizeObservation::do_step(const Value& actions) {
  const VectorStepResult& inner = step_inner(actions);
  view(inner.rewards, step_result_.rewards);
  view(inner.terminated, step_result_.terminated);
  view(inner.truncated, step_result_.truncated);
  copy_infos(inner.infos, step_result_.infos);
  const bool has_final = autoreset_mode() == AutoresetMode::kSameStep &&
                         inner.infos.contains("final_obs") && inner.infos.contains("_final_obs");
  const Value* final_in = has_final ? &inner.infos.at("final_obs") : nullptr;
  transform(wrappers::box_of(inner.obs, where_), nullptr, wrappers::box_of(obs_, where_),
            has_final ? &wrappers::box_of(*final_in, where_) : nullptr,
            has_final ? inner.infos.at("_final_obs").array().data<bool>() : nullptr,
            has_final ? &wrappers::box_of(final_obs_, where_) : nullptr);
  wrappers::copy_other_entries(inner.obs, obs_, where_);
  if (has_final) {
    wrappers::copy_other_entries(*final_in, final_obs_, where_);
    step_result_.infos.insert("final_obs", final_obs_);
  }
  return step_result_;
}

}  // namespace pixelgym::vector
