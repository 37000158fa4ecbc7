// GrayscaleObservation: converts an RGB image observation (a bare image or one key of a Dict)
// to grayscale, as gymnasium.wrappers.GrayscaleObservation, but also on a Dict key.
#pragma once

#include <memory>
#include <string>

#include "pixelgym/envs/wrapper.h"
#include "pixelgym/wrappers/image_key.h"

namespace pixelgym::wrappers {

/// Converts the uint8 (H, W, 3) RGB image under `key` (or the bare image observation) to
/// grayscale with OpenCV's cv::cvtColor(COLOR_RGB2GRAY): ITU-R BT.601 luma,
/// Y = 0.299 R + 0.587 G + 0.114 B, rounded. The output is (H, W), or (H, W, 1) with `keep_dim`;
/// its space is a uint8 Box with bounds [0, 255]. The Dict's other keys pass through untouched.
/// No allocation per step: OpenCV reads and writes the observations' memory through views.
class GrayscaleObservation final : public ObservationWrapper {
 public:
  /// Throws std::invalid_argument as find_image when `key` does not name a uint8 (H, W, 3)
  /// image (an image with 1 channel is already gray and is refused too).
  explicit GrayscaleObservation(std::unique_ptr<Env> env, bool keep_dim = false,
                                const std::string& key = "pixels");

  /// Whether the output keeps a channel axis, (H, W, 1), rather than (H, W).
  bool keep_dim() const { return keep_dim_; }

 protected:
  std::string type_name() const override { return "GrayscaleObservation"; }
  void observation(const Value& in, Value& out) override;

 private:
  bool keep_dim_;
  ImageKey image_;
};

}  // namespace pixelgym::wrappers
