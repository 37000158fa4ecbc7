#include "pixelgym/wrappers/resize_observation.h"

#include <algorithm>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <utility>

namespace pixelgym::wrappers {
namespace {

// A cv::Mat header over an image Array's memory: (H, W) or (H, W, C) uint8.
cv::Mat mat_view(const Array& image) {
  const int channels = image.ndim() == 3 ? static_cast<int>(image.shape()[2]) : 1;
  return cv::Mat(static_cast<int>(image.shape()[0]), static_cast<int>(image.shape()[1]),
                 CV_8UC(channels), const_cast<void*>(image.raw_data()));
}

}  // namespace

ResizeObservation::ResizeObservation(std::unique_ptr<Env> env, ImageSize size,
                                     const std::string& key)
    : ObservationWrapper(std::move(env)), size_(size) {
  if (size.height < 1 || size.width < 1 || size.height > kMaxSide || size.width > kMaxSide) {
    throw std::invalid_argument("ResizeObservation: size must be between 1 and " +
                                std::to_string(kMaxSide) + " on each side, got " +
                                std::to_string(size.height) + "x" + std::to_string(size.width) +
                                " (height x width) for key \"" + key + "\"");
  }
  const Space& inner = env_->observation_space();
  image_ = find_image(inner, key, "ResizeObservation", ImageRequirement{{0, 1, 3}});
  const bool grows = size.height > image_.height() || size.width > image_.width();
  interpolation_ = grows ? cv::INTER_LINEAR : cv::INTER_AREA;
  const bool integer_factors =
      image_.height() % size.height == 0 && image_.width() % size.width == 0;
  if (!grows && !integer_factors) {
    area_.emplace(static_cast<int>(image_.height()), static_cast<int>(image_.width()),
                  static_cast<int>(size.height), static_cast<int>(size.width),
                  static_cast<int>(std::max<std::int64_t>(image_.channels(), 1)));
  }
  Shape shape = {size.height, size.width};
  if (image_.channels() != 0) shape.push_back(image_.channels());
  set_observation_space(replace_image(inner, image_, uint8_image_space(std::move(shape))));
}

void ResizeObservation::observation(const Value& in, Value& out) {
  if (area_) {
    (*area_)(image_of(in, image_).data<std::uint8_t>(), image_of(out, image_).data<std::uint8_t>());
    copy_other_entries(in, out, image_);
    return;
  }
  const cv::Mat source = mat_view(image_of(in, image_));
  cv::Mat target = mat_view(image_of(out, image_));
  const void* const memory = target.data;
  cv::resize(source, target, target.size(), 0.0, 0.0, interpolation_);
  // The target has the size and type asked for, so cv::resize writes into it in place.
  if (target.data != memory)
    throw std::runtime_error("ResizeObservation: cv::resize reallocated its target");
  copy_other_entries(in, out, image_);
}

}  // namespace pixelgym::wrappers
