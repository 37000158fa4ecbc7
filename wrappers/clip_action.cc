#include "pixelgym/wrappers/clip_action.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <utility>

namespace pixelgym::wrappers {
namespace {

template <typename T>
void clip(const Array& in, Array& out, const spaces::Box& box) {
  const T* from = in.data<T>();
  T* to = out.data<T>();
  const std::vector<double>& low = box.low();
  const std::vector<double>& high = box.high();
  for (std::int64_t i = 0; i < in.size(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    // The bounds are already rounded to T (spaces::Box stores them so); NaN passes through.
    const T x = from[i];
    to[i] = x < static_cast<T>(low[k])    ? static_cast<T>(low[k])
            : x > static_cast<T>(high[k]) ? static_cast<T>(high[k])
                                          : x;
  }
}

}  // namespace

ClipAction::ClipAction(std::unique_ptr<Env> env) : ActionWrapper(std::move(env)) {
  const Space& space = env_->action_space();
  inner_ = dynamic_cast<const spaces::Box*>(&space);
  if (inner_ == nullptr || !is_floating(*space.dtype())) {
    throw std::invalid_argument(
        "ClipAction: the action space must be a float32 or float64 Box, got " + space.to_string());
  }
  const double inf = std::numeric_limits<double>::infinity();
  set_action_space(std::make_shared<spaces::Box>(-inf, inf, *space.shape(), *space.dtype()));
}

void ClipAction::action(const Value& action, Value& out) {
  if (action.array().dtype() == DType::kFloat32) {
    clip<float>(action.array(), out.array(), *inner_);
  } else {
    clip<double>(action.array(), out.array(), *inner_);
  }
}

}  // namespace pixelgym::wrappers
