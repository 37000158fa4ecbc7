// ChannelFirstObservation: HWC -> CHW for CNNs (PyTorch's layout), on a bare image or one key
// of a Dict.
#pragma once

#include <memory>
#include <string>

#include "pixelgym/envs/wrapper.h"
#include "pixelgym/wrappers/image_key.h"

namespace pixelgym::wrappers {

/// Transposes the uint8 (H, W, C) image under `key` (or the bare image observation), C = 1 or 3,
/// to (C, H, W): out[c][y][x] = in[y][x][c]. The output space is a uint8 Box with bounds
/// [0, 255]; the Dict's other keys pass through untouched. No allocation per step.
class ChannelFirstObservation final : public ObservationWrapper {
 public:
  /// Throws std::invalid_argument as find_image when `key` does not name a uint8 (H, W, 1) or
  /// (H, W, 3) image.
  explicit ChannelFirstObservation(std::unique_ptr<Env> env, const std::string& key = "pixels");

 protected:
  std::string type_name() const override { return "ChannelFirstObservation"; }
  void observation(const Value& in, Value& out) override;

 private:
  ImageKey image_;
};

}  // namespace pixelgym::wrappers
