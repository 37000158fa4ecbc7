// ResizeObservation: resizes an image observation (a bare image or one key of a Dict) with
// OpenCV, as gymnasium.wrappers.ResizeObservation, but also on a Dict key.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "pixelgym/envs/wrapper.h"
#include "pixelgym/wrappers/area_resize.h"
#include "pixelgym/wrappers/image_key.h"

namespace pixelgym::wrappers {

/// An image's size in pixels.
struct ImageSize {
  /// Rows.
  std::int64_t height = 0;
  /// Columns.
  std::int64_t width = 0;
};

/// Resizes the uint8 image under `key` (or the bare image observation) to `size`, keeping its
/// channels: (H, W, C) -> (height, width, C), (H, W) -> (height, width); C = 1 or 3. The output
/// space is a uint8 Box with bounds [0, 255]; the Dict's other keys pass through untouched.
///
/// Interpolation is OpenCV's INTER_AREA when neither side grows (the anti-aliased choice for
/// shrinking) and INTER_LINEAR when either side grows:
///  - a shrink by integer factors (84 -> 42) and any enlargement: cv::resize, reading and writing
///    through cv::Mat views of the observation's memory. For an enlargement cv::resize allocates
///    two scratch buffers for its tables on each call, which OpenCV gives no way to preallocate;
///    the integer shrink allocates nothing. Throws std::runtime_error should OpenCV ever
///    reallocate the target view.
///  - a shrink by a non-integer factor (84 -> 64): AreaResize, the same area weights with tables
///    and buffers built once (no allocation per step) and rows blended before columns, faster
///    than cv::resize (docs/design-notes.md, "Wrappers"); a value may differ from cv::resize's by
///    one level (float sums in another order).
class ResizeObservation final : public ObservationWrapper {
 public:
  /// The largest height or width accepted.
  static constexpr std::int64_t kMaxSide = 8192;

  /// Throws std::invalid_argument when `size` has a side < 1 or > kMaxSide, and as find_image
  /// when `key` does not name a uint8 (H, W), (H, W, 1) or (H, W, 3) image.
  ResizeObservation(std::unique_ptr<Env> env, ImageSize size, const std::string& key = "pixels");

  /// The output image's size.
  ImageSize size() const { return size_; }

 protected:
  std::string type_name() const override { return "ResizeObservation"; }
  void observation(const Value& in, Value& out) override;

 private:
  ImageSize size_;
  ImageKey image_;
  int interpolation_;               // cv::InterpolationFlags
  std::optional<AreaResize> area_;  // a shrink by a non-integer factor
};

}  // namespace pixelgym::wrappers
