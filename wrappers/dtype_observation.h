// DtypeObservation: casts a Box observation (or one Dict key) to another dtype
// (gymnasium.wrappers.DtypeObservation).
#pragma once

#include <memory>
#include <string>

#include "pixelgym/envs/wrapper.h"
#include "pixelgym/wrappers/box_key.h"

namespace pixelgym::wrappers {

/// Converts the Box under `key` (or the bare Box observation, key "") to `dtype`; the Dict's other
/// keys pass through. The new space is a Box of the same shape and bounds in `dtype`:
/// - to a float dtype: values and bounds as C++ converts them (float64 -> float32 rounds to
///   nearest; a finite bound beyond float32's range becomes infinite);
/// - float to an integer dtype: values are truncated toward zero (numpy's astype) and saturate at
///   the dtype's range, NaN becoming 0; bounds are truncated the same way, so every observation
///   inside the inner Box lands inside the new one;
/// - integer to integer: values saturate at the target's range.
/// An infinite bound, or an integer bound at the source dtype's own limit (an unbounded integer
/// Box), becomes the target dtype's limit. A finite bound the target cannot hold (float bounds
/// [-1, 300] to uint8, say) is refused rather than clipped silently. Allocates nothing per step.
/// (Gymnasium also turns Discrete / MultiBinary spaces into Boxes; here only Boxes are cast.)
class DtypeObservation final : public ObservationWrapper {
 public:
  /// Throws std::invalid_argument for a bool `dtype` (not a Box dtype), as find_box when `key`
  /// does not name a Box, and when a finite bound is outside `dtype`'s range (naming the element,
  /// the bound and the range).
  DtypeObservation(std::unique_ptr<Env> env, DType dtype, const std::string& key = "");

  /// The dtype observations are cast to.
  DType dtype() const { return dtype_; }
  /// The Dict key cast; empty for a bare Box.
  const std::string& key() const { return where_.key; }

 protected:
  std::string type_name() const override { return "DtypeObservation"; }
  void observation(const Value& in, Value& out) override;

 private:
  DType dtype_;
  BoxKey where_;
};

}  // namespace pixelgym::wrappers
