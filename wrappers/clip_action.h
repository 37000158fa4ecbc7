// ClipAction: clips continuous actions into the action space's bounds
// (gymnasium.wrappers.ClipAction).
#pragma once

#include <memory>
#include <string>

#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/wrapper.h"

namespace pixelgym::wrappers {

/// Accepts any finite-or-not action of the inner env's Box shape and dtype and clips each element
/// into the inner Box's [low, high] before the inner env sees it. As in Gymnasium 1.x, the
/// wrapper's action space is Box(-inf, inf) of the inner shape and dtype, so a policy's raw
/// output is in the action space. NaN elements stay NaN (and the inner env refuses them).
/// Allocates nothing per step (the clipped action is written into a buffer the base class owns).
class ClipAction final : public ActionWrapper {
 public:
  /// Throws std::invalid_argument when the inner action space is not a float32 or float64 Box.
  explicit ClipAction(std::unique_ptr<Env> env);

 protected:
  std::string type_name() const override { return "ClipAction"; }
  void action(const Value& action, Value& out) override;

 private:
  const spaces::Box* inner_;  // the inner env's action space
};

}  // namespace pixelgym::wrappers
