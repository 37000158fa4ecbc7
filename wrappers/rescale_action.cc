#include "pixelgym/wrappers/rescale_action.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace pixelgym::wrappers {
namespace {

std::string format(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

template <typename T>
void rescale(const Array& in, Array& out, const std::vector<double>& gradient,
             const std::vector<double>& intercept, const spaces::Box& outer,
             const spaces::Box& inner) {
  const T* from = in.data<T>();
  T* to = out.data<T>();
  for (std::int64_t i = 0; i < in.size(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double a = static_cast<double>(from[i]);
    // The ends map exactly onto the inner bounds (which are already rounded to T); in between,
    // the affine map, kept inside them should rounding step out.
    double x = a <= outer.low()[k]    ? inner.low()[k]
               : a >= outer.high()[k] ? inner.high()[k]
                                      : gradient[k] * a + intercept[k];
    x = std::clamp(x, inner.low()[k], inner.high()[k]);
    to[i] = std::clamp(static_cast<T>(x), static_cast<T>(inner.low()[k]),
                       static_cast<T>(inner.high()[k]));
  }
}

std::vector<double> spread(std::vector<double> values, std::size_t size, const char* name,
                           const Space& inner) {
  if (values.size() == 1 && size != 1) values.assign(size, values[0]);
  if (values.size() != size) {
    throw std::invalid_argument("RescaleAction: " + std::string(name) + " has " +
                                std::to_string(values.size()) + " values, expected 1 or " +
                                std::to_string(size) + " (the elements of the action space " +
                                inner.to_string() + ")");
  }
  return values;
}

}  // namespace

RescaleAction::RescaleAction(std::unique_ptr<Env> env, double min_action, double max_action)
    : RescaleAction(std::move(env), std::vector<double>{min_action},
                    std::vector<double>{max_action}) {}

RescaleAction::RescaleAction(std::unique_ptr<Env> env, std::vector<double> min_action,
                             std::vector<double> max_action)
    : ActionWrapper(std::move(env)) {
  const Space& space = env_->action_space();
  inner_ = dynamic_cast<const spaces::Box*>(&space);
  if (inner_ == nullptr || !is_floating(*space.dtype())) {
    throw std::invalid_argument(
        "RescaleAction: the action space must be a float32 or float64 Box, got " +
        space.to_string());
  }
  if (!inner_->is_bounded()) {
    throw std::invalid_argument(
        "RescaleAction: the action space must have finite bounds to rescale onto, got " +
        space.to_string());
  }
  const std::size_t size = inner_->low().size();
  min_action = spread(std::move(min_action), size, "min_action", space);
  max_action = spread(std::move(max_action), size, "max_action", space);
  for (std::size_t i = 0; i < size; ++i) {
    if (!std::isfinite(min_action[i]) || !std::isfinite(max_action[i]) ||
        !(min_action[i] < max_action[i])) {
      throw std::invalid_argument(
          "RescaleAction: min_action < max_action, both finite, expected; got min_action " +
          format(min_action[i]) + " and max_action " + format(max_action[i]) + " at element " +
          std::to_string(i));
    }
  }
  auto outer = std::make_shared<spaces::Box>(std::move(min_action), std::move(max_action),
                                             *space.shape(), *space.dtype());
  // From the bounds as the Box stores them (rounded to its dtype), so that its low and high map
  // exactly onto the inner ones.
  gradient_.resize(size);
  intercept_.resize(size);
  for (std::size_t i = 0; i < size; ++i) {
    const double from = outer->low()[i];
    const double to = outer->high()[i];
    if (!(from < to)) {
      throw std::invalid_argument(
          "RescaleAction: min_action and max_action are equal once "
          "rounded to " +
          std::string(dtype_name(*space.dtype())) + " at element " + std::to_string(i) + ": " +
          format(from));
    }
    gradient_[i] = (inner_->high()[i] - inner_->low()[i]) / (to - from);
    intercept_[i] = inner_->low()[i] - gradient_[i] * from;
  }
  outer_ = outer.get();
  set_action_space(std::move(outer));
}

void RescaleAction::action(const Value& action, Value& out) {
  if (action.array().dtype() == DType::kFloat32) {
    rescale<float>(action.array(), out.array(), gradient_, intercept_, *outer_, *inner_);
  } else {
    rescale<double>(action.array(), out.array(), gradient_, intercept_, *outer_, *inner_);
  }
}

}  // namespace pixelgym::wrappers
