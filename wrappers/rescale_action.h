// RescaleAction: maps actions from [min_action, max_action] affinely onto the inner env's Box
// bounds (gymnasium.wrappers.RescaleAction).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/wrapper.h"

namespace pixelgym::wrappers {

/// The wrapper's action space is Box(min_action, max_action) of the inner shape and dtype; an
/// action a becomes low + (high - low) * (a - min_action) / (max_action - min_action) for the
/// inner env (computed in double, element by element), clipped into [low, high] so that rounding
/// never steps outside the inner bounds (as Gymnasium clips): min_action maps exactly to low,
/// max_action exactly to high. The bounds are taken as the wrapper's Box stores them (rounded to
/// the dtype). Allocates nothing per step.
class RescaleAction final : public ActionWrapper {
 public:
  /// The same [min_action, max_action] for every element. Throws std::invalid_argument when the
  /// inner action space is not a float32 or float64 Box, when any of its bounds is infinite, or
  /// unless min_action < max_action are both finite.
  RescaleAction(std::unique_ptr<Env> env, double min_action, double max_action);
  /// Per-element bounds in row-major order, one per element of the action (or one, applying to
  /// all). Throws as above, and for a count that matches neither.
  RescaleAction(std::unique_ptr<Env> env, std::vector<double> min_action,
                std::vector<double> max_action);

 protected:
  std::string type_name() const override { return "RescaleAction"; }
  void action(const Value& action, Value& out) override;

 private:
  const spaces::Box* inner_;      // the inner env's action space
  const spaces::Box* outer_;      // this wrapper's (owned by the base class)
  std::vector<double> gradient_;  // inner = gradient * a + intercept, per element
  std::vector<double> intercept_;
};

}  // namespace pixelgym::wrappers
